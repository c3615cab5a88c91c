// Self-convergence and work-precision diagrams (speed-accuracy §4.4), one pair per scene: each engine's
// error against its own finest run (self_error) and the error against the sweep's reference (the soft
// engine at tol 1e-12), both against wall time per simulated second, log–log, one curve per
// engine-variant (and setting); then the horizon of predictability of every curve whose runs part. A
// sweep.csv written before the self-convergence columns gets the reference diagrams only.
import { esc, num, table } from '../lib/html.mjs';
import { isOwnReference } from '../lib/derive.mjs';

// polydyn sweep's threshold of the horizon (cli/cmd_sweep.c SWEEP_HORIZON_THRESHOLD)
const HORIZON_THRESHOLD = 0.1;

export default {
  id: 'work-precision',
  title: 'Self-convergence (each engine against its own finest run)',
  inputs: ['sweep.csv'],
  build(ctx) {
    const wp = ctx.workPrecision;
    if (!wp) return null;
    const anySelf = wp.some((s) => s.self_convergence);
    let html = '';
    if (anySelf)
      html += '<p>Self-convergence: each point is one setting (tolerance or step size; hover for its value), its error the RMS over samples and ' +
        'moving bodies of max(|x − x_ref|/size, rotation angle in rad) against the <em>same engine-variant\'s finest run</em> (polydyn soft, ' +
        'implicit, adaptive, fixed-step and embedded: its adaptive run at tol 1e-12; ODE and Bullet: their own run at the finest step, 1/16000 s, which is their ' +
        'reference and has no point of its own). It measures how far each engine is from what it would compute with an ever finer ' +
        'setting — not from physics, not from the other engines. Cost: the median wall time of the repeats per simulated second. Lower ' +
        `and further left is better. The dashed line is the error the cost table reads (${num(wp[0].target)}). Below each, the same points ` +
        'against polydyn soft at tol 1e-12, where a rigid engine stalls at the difference between its model and the soft one.</p>';
    else
      html += '<p>Each point is one setting (tolerance or step size; hover for its value); cost is the median wall time of the repeats per ' +
        `simulated second. Lower and further left is better. The dashed line is the error the cost table reads (${num(wp[0].target)}).</p>`;
    html += '<p>Points with no error (failed runs) or an error of exactly 0 cannot be drawn on a log axis and are listed below the diagram.' +
      (anySelf ? '' : ' This sweep.csv has no self-convergence columns (written before them): only the error against the reference is shown.') + '</p>';
    for (const s of wp) {
      html += `<div class="chartbox"><h3>${esc(s.scene)}</h3>`;
      if (s.self_convergence) {
        html += `<p class="muted">self-convergence: against ${esc(s.curves.flatMap((c) => c.self_references).filter(unique).map(refName).join(', '))}</p>`;
        html += diagram(ctx, s, 'self_error', 'error against its own finest run');
        html += undrawnList(s, 'self_error');
      }
      html += `<p class="muted">${s.self_convergence ? 'the same points against ' : 'error: ' + esc(s.error_kinds.join(', ')) + '; against '}` +
        `${esc(s.references.map(refName).join(', '))}</p>`;
      html += diagram(ctx, s, 'error', `error against ${s.references.map(refName).join(', ')}`);
      html += undrawnList(s, 'error');
      html += '</div>';
    }
    html = html.replace('<div class="chartbox">', '<div class="charts multi wide">\n<div class="chartbox">') + '</div>';
    if (anySelf) html += horizonTable(wp);
    return {
      html,
      data: wp,
      csv: [{ name: 'work-precision', header: ['scene', 'curve', 'engine', 'variant', 'setting', 'value', 'error', 'wall_seconds', 'wall_per_sim_second', 'steps',
        'self_error', 'self_reference', 'horizon_seconds'],
        rows: wp.flatMap((s) => s.curves.flatMap((c) => c.points.map((p) => [s.scene, c.label, c.engine, c.variant, c.setting, p.value,
          p.error, p.wall_seconds, p.wall_per_sim_second, p.steps, p.self_error, p.self_reference ?? '', p.horizon_seconds]))) }],
    };
  },
};

// One log–log diagram of the points' `key` (error or self_error) against cost, the target as a dashed line.
function diagram(ctx, s, key, yName) {
  const series = s.curves.map((c) => ({
    name: c.label, type: 'line', symbolSize: 7, smooth: false,
    lineStyle: { color: ctx.color(c.ev), width: 2, type: c.setting === 'step' && s.curves.some((d) => d.ev === c.ev && d.setting === 'tol') ? 'dashed' : 'solid' },
    itemStyle: { color: ctx.color(c.ev) },
    data: c.points.filter((p) => drawable(p, key)).map((p) => [p.wall_per_sim_second, p[key], `${c.setting}=${p.value}`]),
  }));
  // the target error as a dashed line across the drawn cost range, carried by the first curve (a series
  // of its own would enter the legend; ECharts draws no {yAxis} mark line on a log axis)
  const xs = series.flatMap((x) => x.data.map((d) => d[0]));
  if (series.length && xs.length) {
    series[0].markLine = { silent: true, symbol: 'none', lineStyle: { color: '#555', type: 'dashed', width: 1.2 },
      label: { formatter: `error ${num(s.target)}`, position: 'end', color: '#555' },
      data: [[{ coord: [Math.min(...xs), s.target] }, { coord: [Math.max(...xs), s.target] }]] };
  }
  return ctx.chart({
    tooltip: { trigger: 'item', formatter: 'point3' },
    legend: { top: 0 },
    grid: { left: 70, right: 80, top: 50, bottom: 55 },
    xAxis: { type: 'log', name: 'wall time per simulated second (s/s)', nameLocation: 'middle', nameGap: 32, axisLabel: { formatter: 'sci' } },
    yAxis: { type: 'log', name: yName, nameLocation: 'middle', nameGap: 50, axisLabel: { formatter: 'sci' } },
    series,
  }, { height: 380 });
}

// The points of a diagram that cannot be drawn, but an engine's own reference (no self_error by design).
function undrawnList(s, key) {
  const undrawn = s.curves.flatMap((c) => c.points.filter((p) => !drawable(p, key) && !(key === 'self_error' && isOwnReference(c, p))).map((p) =>
    `${c.label} ${c.setting}=${num(p.value)}: ${p[key] === null ? 'no error (run failed)' : 'error ' + num(p[key])}`));
  return undrawn.length ? `<p class="muted">Not drawn: ${esc(undrawn.join('; '))}.</p>` : '';
}

// The horizon of predictability: per scene whose runs part from their own finest run, one row per curve
// with the horizon at each setting, loosest to tightest; the scenes where no run parts in one line.
function horizonTable(wp) {
  const scenes = wp.filter((s) => s.self_convergence);
  const parting = scenes.filter((s) => s.has_horizon);
  const steady = scenes.filter((s) => !s.has_horizon).map((s) => s.scene);
  let html = '<h3 id="horizon">Horizon of predictability</h3>' +
    `<p>The first time at which a run is ${num(HORIZON_THRESHOLD)} apart (a tenth of a body size, or ${num(HORIZON_THRESHOLD)} rad) from its ` +
    'engine-variant\'s own finest run, for some moving body. In a chaotic scene (a tumbling box, a pile) runs at different settings agree ' +
    'up to that time and then go separate ways, so no setting converges over the whole run: this time, not an error, is what tightening ' +
    'the setting buys. "never": the run stays within it up to the end; "—": the run is its own reference (or failed).</p>';
  if (parting.length) {
    const rows = [];
    for (const s of parting)
      for (const c of s.curves) {
        const measured = c.points.filter((p) => !isOwnReference(c, p));
        const cells = measured.map((p) => `${c.setting} ${num(p.value)}: ${horizonText(p)}`);
        const finite = measured.filter((p) => p.horizon_seconds !== null);
        const never = measured.filter((p) => p.horizon_seconds === null && p.self_error !== null);
        const from = measured.indexOf(never[0]);
        const longest = !never.length ? (finite.length ? `${num(Math.max(...finite.map((p) => p.horizon_seconds)))} s` : '—') :
          !finite.length ? 'never' :
          measured.slice(from).every((p) => never.includes(p)) ? `never from ${c.setting} ${num(never[0].value)}` :
          `never at ${c.setting} ${never.map((p) => num(p.value)).join(', ')}`;
        rows.push([esc(s.scene), esc(c.label), esc(c.self_references.map(refName).join(', ')),
          { html: esc(cells.join(' · ')), cls: 'muted' }, { html: esc(longest), cls: 'n' }]);
      }
    html += table(['scene', 'engine variant', 'against', 'horizon at each setting, loosest to tightest', 'longest horizon'], rows, 'horizon');
  }
  if (steady.length)
    html += `<p class="legend">No run leaves its own finest run by ${num(HORIZON_THRESHOLD)} in ${esc(steady.join(', '))}: no horizon there ` +
      '(every setting swept predicts the whole run).</p>';
  return html;
}

function horizonText(p) {
  if (p.self_error === null) return '—';
  return p.horizon_seconds === null ? 'never' : `${num(p.horizon_seconds)} s`;
}

function refName(r) {
  const m = /^soft tol=(.*)$/.exec(r || '');
  return m ? `polydyn soft at tol ${m[1]}` : r;
}

function unique(x, k, all) {
  return all.indexOf(x) === k;
}

function drawable(p, key) {
  return Number.isFinite(p[key]) && p[key] > 0 && Number.isFinite(p.wall_per_sim_second) && p.wall_per_sim_second > 0;
}
