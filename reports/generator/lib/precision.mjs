// Work-precision against the closed form (precision.csv of `polydyn gedanken --precision`): per experiment one
// curve per engine-variant and knob, each curve's cost to reach the experiment's own tolerance, and, when no
// setting reaches it, the error floor and why. Pure functions: no file access, no HTML.
import { costToReach, median, orderEngineVariants } from './derive.mjs';
import { num } from './html.mjs';

// Two finest usable points closer than this (relative) mean the error no longer falls with the setting: it
// stalls at a floor that refining does not move (the model or the solver, not the discretisation).
const STALL_RELATIVE_CHANGE = 0.3;

function usable(p) {
  return p.status === 'ok' && Number.isFinite(p.error) && Number.isFinite(p.wall_per_sim_second) && p.wall_per_sim_second > 0;
}

// Why a judged curve never reaches the tolerance, from its points (loosest first).
function neverReason(points) {
  const ok = points.filter(usable);
  if (!ok.length) {
    const statuses = [...new Set(points.map((p) => p.status))];
    return { floor: null, why: 'no_result', text: `no setting gave a result (${statuses.join(', ')})` };
  }
  const floor = Math.min(...ok.map((p) => p.error));
  if (ok.length >= 2) {
    const a = ok[ok.length - 2].error, b = ok[ok.length - 1].error;
    const change = Math.abs(a - b) / Math.max(a, b, Number.MIN_VALUE);
    if (change < STALL_RELATIVE_CHANGE)
      return { floor, why: 'stalls', text: 'the error stalls: refining the setting no longer reduces it (the engine’s model or solver differs from the closed form, not its step)' };
    return { floor, why: 'still_falling', text: 'the error still changes at the finest setting: a finer one might get there, at a higher cost' };
  }
  return { floor, why: 'one_point', text: 'only one setting gave a result' };
}

// {experiments: [...], engine_variants: [...], summary: [...]} from the precision rows and experiments.json (nullable).
export function precision(prec, experiments) {
  const rows = prec.rows;
  const meta = new Map((experiments ? experiments.list : []).map((e) => [e.name, e]));
  const names = [...new Set(rows.map((r) => r.experiment))];
  const order = experiments ? experiments.list.map((e) => e.name) : [];
  names.sort((a, b) => ((order.indexOf(a) + 1) || Infinity) - ((order.indexOf(b) + 1) || Infinity));
  const evs = orderEngineVariants(rows).map((x) => x.ev);
  // one curve per engine-variant and knob (Bullet has two: its step and its solver's iterations), labelled
  // "ENGINE VARIANT (KNOB)" when its engine-variant has more than one
  const knobsOf = (ev) => [...new Set(rows.filter((r) => r.ev === ev && r.setting).map((r) => r.setting))]
    .sort((a, b) => KNOB_ORDER.indexOf(a) - KNOB_ORDER.indexOf(b));
  const curveKeys = evs.flatMap((ev) => {
    const knobs = knobsOf(ev);
    if (!knobs.length) return [{ ev, setting: '', label: ev }];
    return knobs.map((setting) => ({ ev, setting, label: knobs.length > 1 ? `${ev} (${setting})` : ev }));
  });
  const out = names.map((name) => {
    const mine = rows.filter((r) => r.experiment === name);
    const first = mine[0];
    const curves = [];
    for (const { ev, setting, label } of curveKeys) {
      const pts = mine.filter((r) => r.ev === ev && (r.setting === setting || r.status === 'not_built'));
      if (!pts.length) continue;
      // loosest first: the largest tolerance or step, the fewest iterations
      const ordered = [...pts].sort((a, b) => (setting === 'iterations' ? 1 : -1) * ((a.value ?? 0) - (b.value ?? 0)));
      const judged = pts[0].judged;
      const notBuilt = pts.every((p) => p.status === 'not_built');
      // a run that gave no answer counts as outside the tolerance (costToReach: error Infinity)
      const answered = ordered.filter((p) => p.status !== 'not_built' && p.status !== 'refused')
        .map((p) => (usable(p) ? p : { ...p, error: Infinity }));
      const to = notBuilt ? { kind: 'not_built', wall_per_sim_second: null, setting_value: null }
        : costToReach(answered, first.tolerance);
      const curve = {
        label, ev, engine: pts[0].engine, variant: pts[0].variant, setting: pts[0].setting, judged,
        points: ordered.map((p) => ({ value: p.value, measured: p.measured, error: p.error, wall_seconds: p.wall_seconds,
          wall_per_sim_second: p.wall_per_sim_second, cpu_per_sim_second: p.cpu_per_sim_second ?? null, steps: p.steps,
          derivatives: p.derivatives ?? null, steps_limited_by: p.steps_limited_by ?? null,
          status: p.status, note: p.note })),
        to_tolerance: to,
        // the same read on the CPU time, where every usable point has it (precision.csv before it: null)
        to_tolerance_cpu: notBuilt || !ordered.filter(usable).every((p) => Number.isFinite(p.cpu_per_sim_second) && p.cpu_per_sim_second > 0)
          ? null : costToReach(answered.map((p) => ({ ...p, wall_per_sim_second: p.cpu_per_sim_second })), first.tolerance),
        floor: null,
        never: null,
      };
      const ok = ordered.filter(usable);
      curve.floor = ok.length ? Math.min(...ok.map((p) => p.error)) : null;
      if (to.kind === 'never') curve.never = neverReason(ordered);
      curves.push(curve);
    }
    const m = meta.get(name);
    return {
      experiment: name, title: m ? m.title : '', kind: first.kind, quantity: first.quantity, unit: first.unit, input: first.input,
      expected: first.expected, tolerance: first.tolerance, relative: first.relative,
      not_applicable_reason: m && typeof m.not_applicable_reason === 'string' ? m.not_applicable_reason : null, curves,
    };
  });
  return { experiments: out, engine_variants: evs, curves: curveKeys.map((k) => k.label), summary: summarize(out, evs),
    timing: timingProtocol(rows) };
}

// The least CPU time of one timing (gedanken/include/pdgk/gedanken.h, PD_GK_TIMING_MIN_CPU_SECONDS), s.
const TIMING_MIN_CPU_SECONDS = 0.020;

// How the file's costs were taken: the least of `repeats` timings, each the run repeated back to back to a minimum
// CPU time, with the median over the points of their spread (max/min); or, in files from before the timings, the
// median of `repeats` single runs.
function timingProtocol(rows) {
  const ok = rows.filter((r) => r.status === 'ok');
  const repeats = Math.max(0, ...ok.map((r) => r.repeats ?? 0));
  const timed = ok.filter((r) => r.runs_per_timing !== null && r.runs_per_timing !== undefined);
  if (!timed.length) return { kind: 'median_of_runs', repeats, median_cpu_max_over_min: null };
  return { kind: 'least_of_timings', repeats,
    median_cpu_max_over_min: median(timed.map((r) => r.cpu_max_over_min).filter((x) => Number.isFinite(x))) };
}

// What a point's cost is, in a sentence of the report.
export function costProtocolText(timing) {
  if (!timing || timing.kind !== 'least_of_timings')
    return `a point’s cost is the median of its ${timing ? timing.repeats : ''} runs, each timed once`;
  const n = timing.repeats;
  return `a point’s cost is the least of its ${n} timing${n === 1 ? '' : 's'}; a timing repeats the run back to back until it ` +
    `has spent ${TIMING_MIN_CPU_SECONDS * 1e3} ms of CPU time and divides by the runs` +
    (n > 1 ? ` — the minimum of several, as the speed–accuracy protocol asks; precision.csv also has the timings’ median and ` +
      `spread (max/min: a median ${num(timing.median_cpu_max_over_min)} over the points)` : '');
}

const KNOB_ORDER = ['tol', 'step', 'iterations'];

// The cheapest of an engine-variant's curves that reaches the tolerance, else its first curve (its main knob).
export function bestCurve(curves) {
  let best = null;
  for (const c of curves) {
    const t = c.to_tolerance;
    if (t.kind !== 'interpolated' && t.kind !== 'at_most') continue;
    if (!best || t.wall_per_sim_second < best.to_tolerance.wall_per_sim_second) best = c;
  }
  return best || curves[0] || null;
}

// Per engine-variant: how many judged experiments it reaches the tolerance of at some setting, the median cost
// to reach it (over those), the ones it never reaches, the ones not applicable; and its front: at each knob
// setting the median (over the judged experiments) of error/tolerance and of the wall time per simulated second.
function summarize(exps, evs) {
  return evs.map((ev) => {
    const cells = exps.map((e) => ({ e, c: bestCurve(e.curves.filter((c) => c.ev === ev)) })).filter((x) => x.c);
    // the front follows the main knob (the first: tol or step), at whose settings the experiments line up
    const main = exps.map((e) => ({ e, c: e.curves.find((c) => c.ev === ev) })).filter((x) => x.c && x.c.judged &&
      x.c.to_tolerance.kind !== 'not_built');
    const judged = cells.filter((x) => x.c.judged && x.c.to_tolerance.kind !== 'not_built');
    const reached = judged.filter((x) => x.c.to_tolerance.kind === 'interpolated' || x.c.to_tolerance.kind === 'at_most');
    const never = judged.filter((x) => x.c.to_tolerance.kind === 'never');
    const settings = [...new Set(main.flatMap((x) => x.c.points.map((p) => p.value)))].filter((v) => v !== null).sort((a, b) => b - a);
    const front = settings.map((value) => {
      const pts = main.map((x) => ({ p: x.c.points.find((p) => p.value === value), tol: x.e.tolerance })).filter((y) => y.p && usable(y.p));
      return { value, experiments: pts.length, median_error_over_tolerance: median(pts.map((y) => y.p.error / y.tol)),
        median_wall_per_sim_second: median(pts.map((y) => y.p.wall_per_sim_second)) };
    }).filter((f) => f.experiments > 0);
    return {
      ev,
      setting: main.length ? main[0].c.setting : '',
      judged: judged.length,
      reached: reached.length,
      never: never.map((x) => x.e.experiment),
      not_applicable: cells.filter((x) => !x.c.judged).map((x) => x.e.experiment),
      not_built: cells.some((x) => x.c.to_tolerance.kind === 'not_built'),
      median_cost_to_tolerance: median(reached.map((x) => x.c.to_tolerance.wall_per_sim_second)),
      front,
    };
  });
}
