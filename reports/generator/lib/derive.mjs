// The numbers the report shows, derived from the inputs. Pure functions: no file access, no HTML.

// The error at which the cost table reads each work-precision curve (speed-accuracy §4.4: the
// matched-accuracy cost).
export const TARGET_ERROR = 1e-3;

const ENGINE_ORDER = ['soft', 'ode', 'bullet'];
const VARIANT_ORDER = ['implicit', 'adaptive', 'fixed', 'embedded', 'native', 'matched'];
const STATUS_RANK = { PASS: 0, NOT_APPLICABLE: 1, NOT_BUILT: 2, REFUSED: 3, FAIL: 4, ERROR: 5 };

function rank(list, x) {
  const k = list.indexOf(x);
  return k < 0 ? list.length : k;
}

// Engine-variant labels ("soft implicit", "ode native", ...) in a fixed order: soft, ode, bullet,
// then others alphabetically; within an engine implicit (the soft default), adaptive, fixed, embedded, native, matched, then others.
export function orderEngineVariants(items) {
  const seen = new Map();
  for (const it of items) if (!seen.has(it.ev)) seen.set(it.ev, { ev: it.ev, engine: it.engine, variant: it.variant });
  return [...seen.values()].sort((a, b) =>
    rank(ENGINE_ORDER, a.engine) - rank(ENGINE_ORDER, b.engine) || a.engine.localeCompare(b.engine) ||
    rank(VARIANT_ORDER, a.variant) - rank(VARIANT_ORDER, b.variant) || a.variant.localeCompare(b.variant));
}

// Experiments in catalogue order: as listed in experiments.json, then the others of results.csv in
// order of first appearance. Returns [{name, group, title, quantity, unit, meta (experiments.json entry or null)}].
export function orderExperiments(results, experiments) {
  const out = new Map();
  for (const e of experiments ? experiments.list : [])
    out.set(e.name, { name: e.name, group: e.group, title: e.title, quantity: e.quantity, unit: e.unit, meta: e });
  for (const r of results ? results.rows : [])
    if (!out.has(r.experiment))
      out.set(r.experiment, { name: r.experiment, group: r.group, title: r.title, quantity: r.quantity, unit: r.unit, meta: null });
  return [...out.values()];
}

// inputs of one experiment in a stable order: numerically by value, else as text
function compareInputs(a, b) {
  return (a.inputValue ?? Infinity) - (b.inputValue ?? Infinity) || a.input.localeCompare(b.input);
}

// error / tolerance, when both are finite and the tolerance is > 0
export function ratio(row) {
  return Number.isFinite(row.error) && Number.isFinite(row.tolerance) && row.tolerance > 0 ? row.error / row.tolerance : null;
}

// PASS/FAIL matrix: one cell per (experiment, engine-variant) present in results.csv. A cell over
// several inputs has the worst status, the count of passing inputs, and the largest error (with the
// tolerance of that row) and the largest error/tolerance.
export function matrix(results, experiments) {
  const evs = orderEngineVariants(results.rows);
  const exps = orderExperiments(results, experiments).filter((e) => results.rows.some((r) => r.experiment === e.name));
  const cells = [];
  for (const e of exps) {
    for (const { ev, engine, variant } of evs) {
      const rows = results.rows.filter((r) => r.experiment === e.name && r.ev === ev).sort(compareInputs);
      if (rows.length === 0) continue;
      let status = rows[0].status;
      for (const r of rows) if (STATUS_RANK[r.status] > STATUS_RANK[status]) status = r.status;
      let worst = null;
      for (const r of rows)
        if (Number.isFinite(r.error) && (worst === null || r.error > worst.error)) worst = r;
      const ratios = rows.map(ratio).filter((x) => x !== null);
      cells.push({
        experiment: e.name, ev, engine, variant, status,
        not_applicable_reason: status === 'NOT_APPLICABLE' ? notApplicableReason(e, rows) : null,
        inputs: rows.length,
        passed: rows.filter((r) => r.status === 'PASS').length,
        error: worst ? worst.error : null,
        tolerance: worst ? worst.tolerance : null,
        relative: worst ? worst.relative : false,
        error_over_tolerance: ratios.length ? Math.max(...ratios) : null,
        worst_input: worst ? worst.input : '',
        wall_seconds: sum(rows.map((r) => r.wall_seconds)),
        rows: rows.map((r) => r.line),
      });
    }
  }
  return { engine_variants: evs.map((x) => x.ev), experiments: exps.map((e) => e.name), cells };
}

// Why a model prediction is not judged on a variant: experiments.json's reason, else the row's note
// ("not applicable: REASON; …").
function notApplicableReason(e, rows) {
  if (e.meta && typeof e.meta.not_applicable_reason === 'string') return e.meta.not_applicable_reason;
  const m = /^not applicable: ([^;]*)/.exec(rows[0].note);
  return m ? m[1] : '';
}

function sum(xs) {
  const f = xs.filter((x) => Number.isFinite(x));
  return f.length ? f.reduce((a, b) => a + b, 0) : null;
}

export function median(xs) {
  const f = xs.filter((x) => Number.isFinite(x)).sort((a, b) => a - b);
  if (!f.length) return null;
  const m = f.length >> 1;
  return f.length % 2 ? f[m] : (f[m - 1] + f[m]) / 2;
}

// Per engine-variant verdict: cells by status, the worst cell by error/tolerance, wall time. Passes are
// counted over the experiments that apply to the variant (`experiments`); a model prediction measured on a
// variant it does not apply to is listed in not_applicable and never counts as a pass or a failure.
export function verdicts(mat) {
  return mat.engine_variants.map((ev) => {
    const cells = mat.cells.filter((c) => c.ev === ev);
    const by = {};
    for (const s of Object.keys(STATUS_RANK)) by[s] = cells.filter((c) => c.status === s).map((c) => c.experiment);
    let worst = null;
    for (const c of cells) if (c.status !== 'NOT_APPLICABLE' && c.error_over_tolerance !== null && (!worst || c.error_over_tolerance > worst.error_over_tolerance)) worst = c;
    return {
      ev, experiments: cells.length - by.NOT_APPLICABLE.length, pass: by.PASS.length, fail: by.FAIL, error: by.ERROR,
      refused: by.REFUSED, not_built: by.NOT_BUILT, not_applicable: by.NOT_APPLICABLE,
      worst: worst ? { experiment: worst.experiment, input: worst.worst_input, error_over_tolerance: worst.error_over_tolerance } : null,
      total_wall_seconds: sum(cells.map((c) => c.wall_seconds)),
      median_wall_seconds_per_experiment: median(cells.map((c) => c.wall_seconds)),
    };
  });
}

// Restitution table: rows with quantity "restitution"; requested from the input e=… (or
// restitution=…), predicted = expected, measured per engine-variant.
export function restitution(results) {
  const rows = results.rows.filter((r) => r.quantity === 'restitution');
  if (!rows.length) return null;
  const evs = orderEngineVariants(rows).map((x) => x.ev);
  const groups = new Map();
  for (const r of [...rows].sort(compareInputs)) {
    const key = r.experiment + '\u0000' + r.input;
    if (!groups.has(key)) groups.set(key, { experiment: r.experiment, input: r.input,
      requested: r.inputName === 'e' || r.inputName === 'restitution' ? r.inputValue : null,
      predicted: null, measured: {}, status: {} });
    const g = groups.get(key);
    if (g.predicted === null && Number.isFinite(r.expected)) g.predicted = r.expected;
    g.measured[r.ev] = r.measured;
    g.status[r.ev] = r.status;
  }
  return { engine_variants: evs, rows: [...groups.values()] };
}

// Friction cone: rows with quantity "stopping_distance" and input push_deg=…, per experiment: one
// trace per engine-variant and the expected distance, and each trace's spread (max−min)/mean.
export function frictionCone(results) {
  const rows = results.rows.filter((r) => r.quantity === 'stopping_distance' && r.inputName === 'push_deg' && r.inputValue !== null);
  if (!rows.length) return null;
  const out = [];
  for (const exp of [...new Set(rows.map((r) => r.experiment))]) {
    const mine = rows.filter((r) => r.experiment === exp).sort(compareInputs);
    const traces = orderEngineVariants(mine).map(({ ev }) => {
      const pts = mine.filter((r) => r.ev === ev && Number.isFinite(r.measured)).map((r) => ({ push_deg: r.inputValue, distance: r.measured, status: r.status }));
      const d = pts.map((p) => p.distance);
      const mean = d.length ? d.reduce((a, b) => a + b, 0) / d.length : null;
      return { ev, points: pts, spread: d.length > 1 && mean ? (Math.max(...d) - Math.min(...d)) / mean : null };
    });
    const expected = [];
    for (const r of mine)
      if (Number.isFinite(r.expected) && !expected.some((p) => p.push_deg === r.inputValue)) expected.push({ push_deg: r.inputValue, distance: r.expected });
    out.push({ experiment: exp, unit: mine[0].unit, traces, expected });
  }
  return out;
}

// Work-precision curves of sweep.csv, per scene: one curve per engine-variant (split by setting when
// an engine-variant was swept over both tol and step), points ordered from the loosest setting to
// the tightest (value descending). Each curve's cost to reach TARGET_ERROR (`to_target`, what the cost
// table reads) is read on its self-convergence error (self_error: against the engine-variant's own finest
// run) when every row of the scene has that column (`self_convergence`), else — a sweep.csv written before
// it — on its error against the reference; `to_target_reference` is always read on the latter.
export function workPrecision(sweep, target = TARGET_ERROR) {
  const scenes = [...new Set(sweep.rows.map((r) => r.scene))];
  return scenes.map((scene) => {
    const rows = sweep.rows.filter((r) => r.scene === scene);
    const self = rows.every((r) => r.has_self);
    const curves = [];
    for (const { ev, engine, variant } of orderEngineVariants(rows)) {
      const mine = rows.filter((r) => r.ev === ev);
      const settings = [...new Set(mine.map((r) => r.setting))].sort().reverse();  // tol before step
      for (const setting of settings) {
        const pts = mine.filter((r) => r.setting === setting).sort((a, b) => b.value - a.value).map((r) => ({
          value: r.value, error: r.error, wall_seconds: r.wall_seconds, wall_per_sim_second: r.wall_per_sim_second,
          steps: r.steps, repeats: r.repeats, line: r.line, self_error: r.self_error, self_reference: r.self_reference,
          horizon_seconds: r.horizon_seconds }));
        const label = settings.length > 1 ? `${ev} (${setting})` : ev;
        const toReference = costToReach(pts, target);
        curves.push({ label, ev, engine, variant, setting,
          self_references: self ? [...new Set(pts.map((p) => p.self_reference))] : [],
          points: pts,
          to_target: self ? costToReach(pts.map((p) => ({ ...p, error: p.self_error })), target) : toReference,
          to_target_reference: toReference });
      }
    }
    return { scene, self_convergence: self, error_kinds: [...new Set(rows.map((r) => r.error_kind))],
      references: [...new Set(rows.map((r) => r.reference))], target,
      has_horizon: self && rows.some((r) => r.horizon_seconds !== null), curves };
  });
}

// A point's own reference: the run its self_error is measured against is the point itself (an ODE or
// Bullet variant's finest step: no self_error, no horizon).
export function isOwnReference(curve, p) {
  return p.self_reference !== null && p.self_reference === `${curve.engine} ${curve.variant} ${curve.setting}=${formatG(p.value)}`;
}

// C's %.6g for the settings swept (what polydyn sweep writes into self_reference).
function formatG(x) {
  const e = Math.floor(Math.log10(Math.abs(x)));
  if (e < -4 || e >= 6) {
    const [m, ex] = x.toExponential(5).split('e');
    const n = Number(ex);
    return `${m.replace(/\.?0+$/, '')}e${n < 0 ? '-' : '+'}${String(Math.abs(n)).padStart(2, '0')}`;
  }
  return String(Number(x.toPrecision(6)));
}

// Cost (wall seconds per simulated second) at which a curve reaches `target` and stays there, walking from the
// loosest setting to the tightest: the first point at or below the target whose next finer point is too (a point
// within the target between two outside it is luck — an error changing sign, an event rounded the right way —
// not the engine's accuracy), interpolated linearly in log(error)–log(cost) between it and the point before it.
// Where the error falls between the two points faster than cost^-MAX_INTERPOLATED_ORDER, the fall is a change of
// regime (a body frozen asleep, an event missed), not convergence: the crossing could be anywhere between them,
// and the cost is bounded by the point that reaches it. A point whose error is Infinity gave no answer (its run
// failed or its measure found nothing): it is outside the target and nothing is interpolated from it; points with
// no error at all are skipped. {kind: "interpolated"|"at_most"|"never", wall_per_sim_second, setting_value}:
// "at_most" when the loosest point reaches it or nothing can be interpolated (no extrapolation: the cost is at most
// that point's), "never" when no point reaches it.
// Twice the order of the classical RK4 the soft steppers build on: no stepper swept converges faster.
const MAX_INTERPOLATED_ORDER = 8;

export function costToReach(points, target) {
  const usable = points.filter((p) => p.error === Infinity ||
    (Number.isFinite(p.error) && p.error >= 0 && Number.isFinite(p.wall_per_sim_second) && p.wall_per_sim_second > 0));
  const within = (p) => p.error <= target;
  for (let k = 0; k < usable.length; ++k) {
    const p = usable[k];
    if (within(p) && (k + 1 === usable.length || within(usable[k + 1]))) {
      if (k === 0) return { kind: 'at_most', wall_per_sim_second: p.wall_per_sim_second, setting_value: p.value };
      const q = usable[k - 1];
      const order = Math.log(q.error / p.error) / Math.log(p.wall_per_sim_second / q.wall_per_sim_second);
      if (p.error <= 0 || q.error === Infinity || !(order >= 0 && order <= MAX_INTERPOLATED_ORDER))
        return { kind: 'at_most', wall_per_sim_second: p.wall_per_sim_second, setting_value: p.value };
      const s = (Math.log(target) - Math.log(q.error)) / (Math.log(p.error) - Math.log(q.error));
      const w = Math.exp(Math.log(q.wall_per_sim_second) + s * (Math.log(p.wall_per_sim_second) - Math.log(q.wall_per_sim_second)));
      return { kind: 'interpolated', wall_per_sim_second: w, setting_value: null };
    }
  }
  return { kind: 'never', wall_per_sim_second: null, setting_value: null };
}

// Cost table: per engine-variant, the wall time of the Gedanken runs (total and median per
// experiment) and, per swept scene, the cost to reach the target error (the cheapest of its curves): the
// self-convergence error where the sweep has it (self_convergence[scene]), else the error against its reference.
export function cost(mat, wp) {
  const evs = orderEngineVariants([
    ...(mat ? mat.cells : []).map((c) => ({ ev: c.ev, engine: c.engine, variant: c.variant })),
    ...(wp || []).flatMap((s) => s.curves.map((c) => ({ ev: c.ev, engine: c.engine, variant: c.variant })))]).map((x) => x.ev);
  const scenes = (wp || []).map((s) => s.scene);
  const rows = evs.map((ev) => {
    const cells = mat ? mat.cells.filter((c) => c.ev === ev) : [];
    const to_target = {};
    for (const s of wp || []) {
      const curves = s.curves.filter((c) => c.ev === ev);
      if (!curves.length) { to_target[s.scene] = null; continue; }
      let best = null;
      for (const c of curves) {
        const t = c.to_target;
        if (t.kind === 'never') continue;
        if (!best || t.wall_per_sim_second < best.wall_per_sim_second) best = { ...t, curve: c.label };
      }
      to_target[s.scene] = best || { kind: 'never', wall_per_sim_second: null, setting_value: null, curve: null };
    }
    return {
      ev,
      experiments: cells.filter((c) => c.status !== 'REFUSED' && c.status !== 'NOT_BUILT').length,
      total_wall_seconds: sum(cells.map((c) => c.wall_seconds)),
      median_wall_seconds_per_experiment: median(cells.map((c) => c.wall_seconds)),
      to_target,
    };
  });
  const self_convergence = Object.fromEntries((wp || []).map((s) => [s.scene, s.self_convergence]));
  return { scenes, self_convergence, target: wp && wp.length ? wp[0].target : TARGET_ERROR, rows };
}

// Flattens a JSON object into [key, value] pairs with dotted keys; arrays of numbers stay one value.
export function flatten(obj, prefix = '', out = []) {
  for (const [k, v] of Object.entries(obj)) {
    const key = prefix ? `${prefix}.${k}` : k;
    if (v && typeof v === 'object' && !Array.isArray(v)) flatten(v, key, out);
    else out.push([key, v]);
  }
  return out;
}

// Parameters every engine-variant actually used, deduplicated over its runs. For each run with a
// summary: the reference engines' engine_settings, or polydyn's settings, stepper, materials as used
// (one row per distinct material, with the bodies that had it), the contact constants of each pair of
// materials (contact_pairs: springs, dampers, time scales; one row per distinct pair) and adjustments.
// Each distinct value lists the runs that used it.
export function parameters(runs) {
  const byEv = new Map();
  for (const run of runs) {
    if (!byEv.has(run.ev)) byEv.set(run.ev, { ev: run.ev, runs: [], missing: [], settings: new Map(), materials: new Map(), pairs: new Map(), adjustments: new Map() });
    const p = byEv.get(run.ev);
    if (!run.summary) { p.missing.push(run.label); continue; }
    p.runs.push(run.label);
    const s = run.summary;
    const add = (map, key, value, who) => {
      if (!map.has(key)) map.set(key, new Map());
      const vs = map.get(key);
      const text = typeof value === 'string' ? value : JSON.stringify(value);
      if (!vs.has(text)) vs.set(text, []);
      if (!vs.get(text).includes(who)) vs.get(text).push(who);
    };
    if (s.engine_settings) {
      for (const [k, v] of flatten(s.engine_settings)) add(p.settings, k, v, run.label);
    } else {
      if (s.stepper !== undefined) add(p.settings, 'stepper', s.stepper, run.label);
      if (s.settings && typeof s.settings === 'object') for (const [k, v] of flatten(s.settings)) add(p.settings, k, v, run.label);
      for (const b of Array.isArray(s.bodies) ? s.bodies : []) {
        const used = b && b.material && b.material.used;
        if (!used) continue;
        const m = { mu: used.mu, kn: used.kn, kt: used.kt, cn: used.cn, ct: used.ct, restitution: used.restitution, zeta: used.zeta };
        const req = b.material.requested ? Object.entries(b.material.requested).filter(([, v]) => v !== null) : [];
        const key = JSON.stringify({ used: m, requested: Object.fromEntries(req) });
        if (!p.materials.has(key)) p.materials.set(key, { used: m, requested: Object.fromEntries(req), bodies: [] });
        p.materials.get(key).bodies.push(`${run.label}: ${b.name}`);
      }
      for (const c of Array.isArray(s.contact_pairs) ? s.contact_pairs : []) {
        if (!c || typeof c !== 'object') continue;
        const { bodies, ...used } = c;
        const key = JSON.stringify(used);
        if (!p.pairs.has(key)) p.pairs.set(key, { used, bodies: [] });
        p.pairs.get(key).bodies.push(`${run.label}: ${Array.isArray(bodies) ? bodies.join(' / ') : '?'}`);
      }
      for (const a of Array.isArray(s.adjustments) ? s.adjustments : []) add(p.adjustments, String(a), '', run.label);
    }
  }
  return [...byEv.values()].map((p) => ({
    ev: p.ev,
    runs: p.runs,
    missing: p.missing,
    settings: [...p.settings.entries()].map(([key, vs]) => ({ key, values: [...vs.entries()].map(([value, used_by]) => ({ value, used_by })) })),
    materials: [...p.materials.values()],
    pairs: [...p.pairs.values()],
    adjustments: [...p.adjustments.entries()].map(([text, vs]) => ({ text, used_by: [...vs.values()][0] })),
  }));
}
