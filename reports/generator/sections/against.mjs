// What polydyn's answers cost against the rigid engines', on the report's first screen: over the experiments that
// polydyn (its default stepper) and another engine-variant both reach at the experiment's tolerance, the median of
// polydyn's cost over the other's, how often polydyn is the cheaper, the target the project set, and per experiment
// the ratios with what bounds polydyn's cost there. The cost is the CPU time per simulated second where
// precision.csv has it (a loaded machine inflates the wall time of a long run more than that of a sub-millisecond
// one, so wall-time ratios drift with the load), else the wall time.
import { esc, num, table } from '../lib/html.mjs';
import { median } from '../lib/derive.mjs';
import { STEP_LIMITS } from '../lib/inputs.mjs';
import { costProtocolText } from '../lib/precision.mjs';

const SOFT = 'soft implicit';
// The project's targets for the median ratio (docs/validation.md, "Cost against the rigid engines").
const TARGETS = { 'ode native': 3, 'ode matched': 2 };
const OTHERS = ['ode native', 'ode matched', 'bullet native', 'bullet matched'];

// The cheapest reach of an engine-variant's judged curves on one experiment, in `unit` ('cpu' or 'wall'), or null.
function reach(e, ev, unit) {
  let best = null;
  for (const c of e.curves.filter((x) => x.ev === ev && x.judged)) {
    const t = unit === 'cpu' ? c.to_tolerance_cpu : c.to_tolerance;
    if (!t || (t.kind !== 'interpolated' && t.kind !== 'at_most')) continue;
    if (!best || t.wall_per_sim_second < best.cost) {
      const at = t.kind === 'at_most' ? c.points.find((p) => p.value === t.setting_value) : null;
      best = { cost: t.wall_per_sim_second, kind: t.kind, setting: c.setting, value: t.setting_value, loosest: c.points[0].value,
        steps: at ? at.steps : null, derivatives: at ? at.derivatives ?? null : null,
        limited: at ? at.steps_limited_by ?? null : null,
        // simulated seconds of the run (the scene's tend), from the point's wall time and its rate
        tend: at && at.wall_per_sim_second > 0 ? at.wall_seconds / at.wall_per_sim_second : null };
    }
  }
  return best;
}

// What each step limit means, in the words of the per-experiment table, and why it costs steps where it dominates.
const LIMIT_WORDS = {
  error: 'the error control',
  largest: 'the largest step (dtmax)',
  stability: 'the contacts’ stability bound',
  travel: 'the tunnelling guard',
  event: 'contact events (onsets located, stick–slip changes refined)',
  landing: 'sync times between islands',
};
const LIMIT_WHY = {
  error: 'the error control sets the steps even at the loosest tolerance',
  largest: 'the scene’s largest step, dtmax, holds its free flight to shorter steps than the rigid engine’s',
  stability: 'a soft contact must resolve each contact period: an explicit step is stable only below ~2.8/ω',
  travel: 'the tunnelling guard lets a touching pair move at most 2 δ_max (or a quarter of the thinner width) per step',
  event: 'a soft contact must resolve each impact: its onset is located and the steps after it grow from the cut',
  landing: 'the islands’ sync times end its steps',
};

// The limits that set at least 5 % of the steps, largest first.
function mainLimits(limited) {
  const total = STEP_LIMITS.reduce((a, l) => a + limited[l], 0);
  if (!(total > 0)) return [];
  return STEP_LIMITS.filter((l) => limited[l] >= 0.05 * total).sort((a, b) => limited[b] - limited[a])
    .map((l) => ({ limit: l, share: limited[l] / total }));
}

// Why polydyn's cost on an experiment is what it is, from where its curve reaches the tolerance and the other's, and
// what set the size of its steps there (precision.csv's steps_* columns, where it has them).
function bound(soft, other) {
  if (soft.kind !== 'at_most') return 'the error control: a tighter tolerance is needed to reach the answer';
  // "at most" is read at the loosest setting, or at the first that reaches the answer and stays (costToReach)
  const rigid = other && other.kind === 'at_most' && other.setting === 'step' && other.value === other.loosest
    ? '; the rigid engine’s coarsest step reaches it too (a rigid contact resolves an impact within one step)' : '';
  const main = soft.limited && soft.tend > 0 ? mainLimits(soft.limited) : [];
  if (soft.value !== soft.loosest) {
    const from = `it reaches the answer and stays within it from tol ${num(soft.value)} (looser ones miss it, or meet it by chance)`;
    return main.length ? `${from}; there its steps are set by ${main.map((m) => `${Math.round(100 * m.share)} % ${LIMIT_WORDS[m.limit]}`).join(', ')}${rigid}` : from + rigid;
  }
  if (!main.length)
    return 'its loosest tolerance already reaches the answer: the steps resolve the contacts (a soft contact must resolve each ' +
      'impact and each contact period, whatever the tolerance), not the error' + rigid;
  const rate = (n) => num(n / soft.tend);
  return `its loosest tolerance already reaches the answer, so the error control does not set the cost: ${rate(soft.steps)} steps ` +
    'per simulated second' + (other && other.steps !== null && other.tend > 0 ? ` (the rigid engine: ${num(other.steps / other.tend)})` : '') +
    (soft.derivatives !== null ? `, ${rate(soft.derivatives)} derivative evaluations` : '') +
    `, their size set by ${main.map((m) => `${Math.round(100 * m.share)} % ${LIMIT_WORDS[m.limit]}`).join(', ')}: ` +
    `${LIMIT_WHY[main[0].limit]}${rigid}`;
}

export default {
  id: 'against',
  title: 'Cost against the rigid engines',
  inputs: ['precision.csv'],
  build(ctx) {
    const pr = ctx.precision;
    if (!pr || !pr.engine_variants.includes(SOFT)) return null;
    const hasCpu = pr.experiments.some((e) => e.curves.some((c) => c.ev === SOFT && c.to_tolerance_cpu));
    const unit = hasCpu ? 'cpu' : 'wall';
    const others = OTHERS.filter((ev) => pr.engine_variants.includes(ev));
    const perExperiment = pr.experiments.map((e) => {
      const soft = reach(e, SOFT, unit);
      const ratios = {};
      const wallRatios = {};
      for (const ev of others) {
        const o = reach(e, ev, unit), ow = reach(e, ev, 'wall'), sw = reach(e, SOFT, 'wall');
        ratios[ev] = soft && o ? { ratio: soft.cost / o.cost, other: o } : null;
        wallRatios[ev] = sw && ow ? sw.cost / ow.cost : null;
      }
      return { experiment: e.experiment, soft, ratios, wallRatios };
    }).filter((x) => x.soft);
    const summary = others.map((ev) => {
      const both = perExperiment.filter((x) => x.ratios[ev]);
      const r = both.map((x) => x.ratios[ev].ratio);
      const w = perExperiment.map((x) => x.wallRatios[ev]).filter((x) => x !== null);
      const med = median(r);
      return { ev, both: both.length, median_ratio: med, median_wall_ratio: median(w), cheaper: r.filter((x) => x < 1).length,
        target: TARGETS[ev] ?? null, met: TARGETS[ev] === undefined || med === null ? null : med <= TARGETS[ev] };
    });
    const what = hasCpu ? 'CPU time' : 'wall time';
    let html = `<p>Over the experiments that polydyn (${esc(SOFT)}, the default) and the other engine-variant both reach at the ` +
      `experiment’s tolerance: the median of polydyn’s cost to reach it over the other’s (${what} per simulated second` +
      `${hasCpu ? '; the wall-time median beside it' : ''}), and on how many polydyn is the cheaper. Every engine is timed alike: ` +
      `${esc(costProtocolText(pr.timing))}.</p>`;
    html += table(['against', 'experiments both reach', `median cost ratio (${what})`, ...(hasCpu ? ['median ratio (wall time)'] : []),
      'polydyn cheaper on', 'target'], summary.map((s) => [
      { html: esc(s.ev) },
      { html: String(s.both), cls: 'n' },
      { html: s.median_ratio === null ? '—' : `${num(s.median_ratio)}×`, cls: 'n' + (s.met === false ? ' bad' : '') },
      ...(hasCpu ? [{ html: s.median_wall_ratio === null ? '—' : `${num(s.median_wall_ratio)}×`, cls: 'n muted' }] : []),
      { html: `${s.cheaper} of ${s.both}`, cls: 'n' },
      { html: s.target === null ? '—' : `≤ ${s.target}× ${s.met ? '(met)' : '(not met)'}`, cls: 'n' + (s.met === false ? ' bad' : '') },
    ]), 'against-table');
    const rows = [...perExperiment].sort((a, b) => (b.ratios['ode native']?.ratio ?? 0) - (a.ratios['ode native']?.ratio ?? 0));
    html += '<h3>Per experiment</h3>';
    html += table(['experiment', ...others.map((ev) => `÷ ${ev}`), 'polydyn reaches it at', 'what bounds polydyn’s cost'],
      rows.map((x) => {
        const over = (x.ratios['ode native'] && x.ratios['ode native'].ratio > TARGETS['ode native']) ||
          (x.ratios['ode matched'] && x.ratios['ode matched'].ratio > TARGETS['ode matched']);
        return [
          { html: esc(x.experiment) },
          ...others.map((ev) => ({ html: x.ratios[ev] ? `${num(x.ratios[ev].ratio)}×` : '—', cls: 'n' +
            (TARGETS[ev] !== undefined && x.ratios[ev] && x.ratios[ev].ratio > TARGETS[ev] ? ' bad' : '') })),
          { html: `${x.soft.kind === 'at_most' ? '≤ ' : ''}${num(x.soft.cost)} s/s${x.soft.kind === 'at_most'
            ? ` (tol ${num(x.soft.value)}${x.soft.steps !== null ? `, ${x.soft.steps} steps` : ''})` : ''}`, cls: 'n' },
          { html: over ? esc(bound(x.soft, x.ratios['ode native']?.other)) : '<span class="muted">within the targets</span>' },
        ];
      }), 'against-experiments');
    html += '<p class="legend">Ratio: polydyn’s cost to reach the experiment’s tolerance over the other engine-variant’s (each the cheaper ' +
      'of its knobs; “—”: one of the two never reaches it, or the experiment does not judge that variant). Read on the work-precision curves ' +
      'below (Work-precision against the closed form).</p>';
    return {
      html,
      data: { unit, timing: pr.timing, summary, experiments: perExperiment.map((x) => ({ experiment: x.experiment, soft: x.soft,
        ratios: Object.fromEntries(others.map((ev) => [ev, x.ratios[ev] ? x.ratios[ev].ratio : null])) })) },
      csv: [{ name: 'against', header: ['experiment', 'unit', ...others.map((ev) => `ratio_${ev.replace(' ', '_')}`), 'soft_cost',
        'soft_to_tolerance', 'soft_setting_value', 'soft_steps', 'soft_derivatives', ...STEP_LIMITS.map((l) => `soft_steps_${l}`)],
      rows: [
        ...summary.map((s) => [`median over ${s.both} (${s.ev})`, unit, ...others.map((ev) => (ev === s.ev ? s.median_ratio : '')), '', '', '', '',
          '', ...STEP_LIMITS.map(() => '')]),
        ...perExperiment.map((x) => [x.experiment, unit, ...others.map((ev) => (x.ratios[ev] ? x.ratios[ev].ratio : '')), x.soft.cost,
          x.soft.kind, x.soft.value, x.soft.steps, x.soft.derivatives, ...STEP_LIMITS.map((l) => (x.soft.limited ? x.soft.limited[l] : ''))]),
      ] }],
    };
  },
};
