// The numbers of the cube-toss section (the results of `polydyn cubetoss`, read by readCubetoss):
// which parameter set and split the headline shows, the typical toss, the distribution of the end
// errors, and the typical toss's errors over time against the record.
import fs from 'node:fs';
import path from 'node:path';
import { readSummary, readBodyTrajectory } from './inputs.mjs';
import { InputError } from './errors.mjs';
import { median, orderEngineVariants } from './derive.mjs';

export const DEG = 180 / Math.PI;

// The split the headline table and charts use: the tosses not used for fitting when there are any.
export function headlineSplit(summary) {
  return summary.some((r) => r.split === 'test') ? 'test' : 'all';
}

// Parameter sets in order: default, fitted, then the others as they first appear.
export function paramsOrder(rows) {
  const seen = [...new Set(rows.map((r) => r.params))];
  const rank = (p) => (p === 'default' ? 0 : p === 'fitted' ? 1 : 2);
  return seen.map((p, k) => [p, k]).sort((a, b) => rank(a[0]) - rank(b[0]) || a[1] - b[1]).map((x) => x[0]);
}

// The parameter set of the typical toss: fitted when there, else default, else the first.
export function typicalParams(rows) {
  const order = paramsOrder(rows);
  return order.includes('fitted') ? 'fitted' : order[0];
}

// The typical toss: of the tosses in `split` that the first engine (soft when there) completed with
// `params`, the one whose end position error is nearest that engine's median; among the tosses with a
// replay (hasReplay(toss)) when there are any. Ties go to the lower toss number.
export function typicalToss(perToss, { params, split }, hasReplay) {
  const evs = orderEngineVariants(perToss);
  if (!evs.length) return null;
  const ev = evs[0].ev;
  const rows = perToss.filter((r) => r.params === params && (split === 'all' || r.split === split) && r.ev === ev && r.status === 'ok');
  if (!rows.length) return null;
  const m = median(rows.map((r) => r.pos_err_end));
  const withReplay = rows.filter((r) => hasReplay(r.toss));
  const pool = withReplay.length ? withReplay : rows;
  const best = pool.slice().sort((a, b) => Math.abs(a.pos_err_end - m) - Math.abs(b.pos_err_end - m) || a.toss - b.toss)[0];
  return { toss: best.toss, ev, params, split, median: m, pos_err_end: best.pos_err_end, tosses: rows.length,
    replay: withReplay.length > 0 };
}

// Where the run directories of toss T are, relative to the cube-toss directory: replay/T (the
// committed layout of scripts/cubetoss-all) or runs/T (what polydyn cubetoss --out writes); null if neither
// has the record.
export function replayBase(cubetossDir, toss) {
  for (const base of [`replay/${toss}`, `runs/${toss}`])
    if (fs.existsSync(path.join(cubetossDir, base, 'record', 'trajectory.csv'))) return base;
  return null;
}

// Reads the typical toss's record and each engine's run (their summary.json and the moving body's
// trajectory); every problem is an InputError before anything is written. Returns null without
// per_toss.csv, else { toss, ..., body, width, runs: [{ name, label, ev, run_dir (relative to DIR), samples }],
// missing: [engine-variants without a run directory] }.
export function loadTypical(dir, ct) {
  if (!ct.perToss || !ct.perToss.length) return null;
  const root = path.join(dir, ct.at);
  const split = headlineSplit(ct.summary);
  const params = typicalParams(ct.perToss);
  const typical = typicalToss(ct.perToss, { params, split }, (toss) => replayBase(root, toss) !== null);
  if (!typical) return null;
  const base = typical.replay ? replayBase(root, typical.toss) : null;
  const out = { ...typical, base, body: null, width: null, runs: [], missing: [] };
  if (!base) return out;
  const rel = (name) => path.posix.join(ct.at === '.' ? '' : ct.at, base, name);
  const record = readSummary(dir, rel('record'));
  if (!record) throw new InputError(path.join(root, base, 'record', 'summary.json'), 0, 'missing (the record of the typical toss)');
  const moving = Array.isArray(record.summary.bodies) ? record.summary.bodies.find((b) => b && b.fixed === false) : null;
  const vertices = moving && moving.shape && Array.isArray(moving.shape.vertices) ? moving.shape.vertices : null;
  if (!moving || typeof moving.name !== 'string' || !vertices || !vertices.length || !vertices.every((v) => Array.isArray(v) && Number.isFinite(v[0])))
    throw new InputError(record.file, 1, 'the record has no moving body with a shape (bodies[].fixed false, shape.vertices)');
  out.body = moving.name;
  // the cube's width: its extent along its own x axis (the unit of the position errors)
  out.width = Math.max(...vertices.map((v) => v[0])) - Math.min(...vertices.map((v) => v[0]));
  if (!(out.width > 0)) throw new InputError(record.file, 1, `body '${moving.name}' has no extent along x`);
  const runs = [{ name: 'record', label: 'record', ev: null }];
  for (const r of ct.perToss) {
    if (r.toss !== typical.toss || r.params !== params || !r.run_dir || r.status !== 'ok') continue;
    const name = r.run_dir.split('/').pop();
    if (runs.some((x) => x.name === name)) continue;
    if (fs.existsSync(path.join(root, base, name, 'trajectory.csv'))) runs.push({ name, label: r.ev, ev: r.ev });
    else out.missing.push(r.ev);
  }
  for (const run of runs) {
    run.run_dir = rel(run.name);
    const traj = readBodyTrajectory(dir, run.run_dir, moving.name);
    if (!traj || !traj.samples.length) throw new InputError(path.join(dir, run.run_dir, 'trajectory.csv'), 0, `no samples of body '${moving.name}'`);
    run.samples = traj.samples;
  }
  out.runs = runs;
  return out;
}

// Angle of q_ref⁻¹ q in rad, [0, π], as validation/cubetoss_sim.c computes it (atan2 keeps small angles exact).
export function rotationAngle(q, ref) {
  const [w0, x0, y0, z0] = ref, [w1, x1, y1, z1] = q;
  // conj(ref) * q
  const w = w0 * w1 + x0 * x1 + y0 * y1 + z0 * z1;
  const x = w0 * x1 - x0 * w1 - y0 * z1 + z0 * y1;
  const y = w0 * y1 + x0 * z1 - y0 * w1 - z0 * x1;
  const z = w0 * z1 - x0 * y1 + y0 * x1 - z0 * w1;
  return 2 * Math.atan2(Math.hypot(x, y, z), Math.abs(w));
}

// Sample times of a run and the record agree to round-off (both k/148 Hz), s.
const SAMPLE_TIME_TOL = 1e-9;

// Position error (widths) and rotation error (rad) of `run` against `record` at the record's samples
// (a run sample is used only when its time equals the record's to SAMPLE_TIME_TOL).
export function errorsOverTime(record, run, width) {
  const out = [];
  let j = 0;
  for (const s of record) {
    while (j < run.length && run[j].t < s.t - SAMPLE_TIME_TOL) ++j;
    if (j === run.length) break;
    if (Math.abs(run[j].t - s.t) > SAMPLE_TIME_TOL) continue;
    const d = Math.hypot(run[j].x[0] - s.x[0], run[j].x[1] - s.x[1], run[j].x[2] - s.x[2]);
    out.push({ t: s.t, pos: d / width, rot: rotationAngle(run[j].q, s.q) });
  }
  return out;
}

// Empirical distribution: [[x, fraction of values ≤ x]] at each sorted value.
export function ecdf(values) {
  const v = values.filter(Number.isFinite).sort((a, b) => a - b);
  return v.map((x, k) => [x, (k + 1) / v.length]);
}
