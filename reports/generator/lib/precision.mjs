// Work-precision against the closed form (precision.csv of `polydyn gedanken --precision`): per experiment one
// curve per engine-variant and knob, each curve's cost to reach the experiment's own tolerance, and, when no
// setting reaches it, the error floor and why. Pure functions: no file access, no HTML.
import { costToReach, median, orderEngineVariants } from './derive.mjs';

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
  const out = names.map((name) => {
    const mine = rows.filter((r) => r.experiment === name);
    const first = mine[0];
    const curves = [];
    for (const ev of evs) {
      const pts = mine.filter((r) => r.ev === ev);
      if (!pts.length) continue;
      const ordered = [...pts].sort((a, b) => (b.value ?? 0) - (a.value ?? 0));  // loosest first
      const judged = pts[0].judged;
      const notBuilt = pts.every((p) => p.status === 'not_built');
      const to = notBuilt ? { kind: 'not_built', wall_per_sim_second: null, setting_value: null }
        : costToReach(ordered.filter(usable), first.tolerance);
      const curve = {
        ev, engine: pts[0].engine, variant: pts[0].variant, setting: pts[0].setting, judged,
        points: ordered.map((p) => ({ value: p.value, measured: p.measured, error: p.error, wall_seconds: p.wall_seconds,
          wall_per_sim_second: p.wall_per_sim_second, steps: p.steps, status: p.status, note: p.note })),
        to_tolerance: to,
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
  return { experiments: out, engine_variants: evs, summary: summarize(out, evs) };
}

// Per engine-variant: how many judged experiments it reaches the tolerance of at some setting, the median cost
// to reach it (over those), the ones it never reaches, the ones not applicable; and its front: at each knob
// setting the median (over the judged experiments) of error/tolerance and of the wall time per simulated second.
function summarize(exps, evs) {
  return evs.map((ev) => {
    const cells = exps.map((e) => ({ e, c: e.curves.find((c) => c.ev === ev) })).filter((x) => x.c);
    const judged = cells.filter((x) => x.c.judged && x.c.to_tolerance.kind !== 'not_built');
    const reached = judged.filter((x) => x.c.to_tolerance.kind === 'interpolated' || x.c.to_tolerance.kind === 'at_most');
    const never = judged.filter((x) => x.c.to_tolerance.kind === 'never');
    const settings = [...new Set(judged.flatMap((x) => x.c.points.map((p) => p.value)))].filter((v) => v !== null).sort((a, b) => b - a);
    const front = settings.map((value) => {
      const pts = judged.map((x) => ({ p: x.c.points.find((p) => p.value === value), tol: x.e.tolerance })).filter((y) => y.p && usable(y.p));
      return { value, experiments: pts.length, median_error_over_tolerance: median(pts.map((y) => y.p.error / y.tol)),
        median_wall_per_sim_second: median(pts.map((y) => y.p.wall_per_sim_second)) };
    }).filter((f) => f.experiments > 0);
    return {
      ev,
      setting: cells.length ? cells[0].c.setting : '',
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
