// Work-precision diagrams (speed-accuracy §4.4): error against wall time per simulated second,
// log–log, one curve per engine-variant (and setting), one diagram per scene.
import { esc, num } from '../lib/html.mjs';

export default {
  id: 'work-precision',
  title: 'Work-precision',
  inputs: ['sweep.csv'],
  build(ctx) {
    const wp = ctx.workPrecision;
    if (!wp) return null;
    let html = '<p>Each point is one setting (tolerance or step size; hover for its value); cost is the median wall time of the ' +
      'repeats per simulated second. Lower and further left is better. The dashed line is the error the cost table reads ' +
      `(${num(wp[0].target)}). Points with no error (failed runs) or an error of exactly 0 cannot be drawn on a log axis and are listed below the diagram.</p>`;
    for (const s of wp) {
      const series = s.curves.map((c) => ({
        name: c.label, type: 'line', symbolSize: 7, smooth: false,
        lineStyle: { color: ctx.color(c.ev), width: 2, type: c.setting === 'step' && s.curves.some((d) => d.ev === c.ev && d.setting === 'tol') ? 'dashed' : 'solid' },
        itemStyle: { color: ctx.color(c.ev) },
        data: c.points.filter(drawable).map((p) => [p.wall_per_sim_second, p.error, `${c.setting}=${p.value}`]),
      }));
      // the target error as a dashed line across the drawn cost range, carried by the first curve (a series
      // of its own would enter the legend; ECharts draws no {yAxis} mark line on a log axis)
      const xs = series.flatMap((x) => x.data.map((d) => d[0]));
      if (series.length && xs.length) {
        series[0].markLine = { silent: true, symbol: 'none', lineStyle: { color: '#555', type: 'dashed', width: 1.2 },
          label: { formatter: `error ${num(s.target)}`, position: 'end', color: '#555' },
          data: [[{ coord: [Math.min(...xs), s.target] }, { coord: [Math.max(...xs), s.target] }]] };
      }
      html += `<div class="chartbox"><h3>${esc(s.scene)}</h3>`;
      html += `<p class="muted">error: ${esc(s.error_kinds.join(', '))}; reference: ${esc(s.references.join(', '))}</p>`;
      html += ctx.chart({
        tooltip: { trigger: 'item', formatter: 'point3' },
        legend: { top: 0 },
        grid: { left: 70, right: 80, top: 50, bottom: 55 },
        xAxis: { type: 'log', name: 'wall time per simulated second (s/s)', nameLocation: 'middle', nameGap: 32, axisLabel: { formatter: 'sci' } },
        yAxis: { type: 'log', name: 'error', nameLocation: 'middle', nameGap: 50, axisLabel: { formatter: 'sci' } },
        series,
      }, { height: 380 });
      const undrawn = s.curves.flatMap((c) => c.points.filter((p) => !drawable(p)).map((p) =>
        `${c.label} ${c.setting}=${num(p.value)}: ${p.error === null ? 'no error (run failed)' : 'error ' + num(p.error)}`));
      if (undrawn.length) html += `<p class="muted">Not drawn: ${esc(undrawn.join('; '))}.</p>`;
      html += '</div>';
    }
    html = html.replace('<div class="chartbox">', '<div class="charts multi wide">\n<div class="chartbox">') + '</div>';
    return {
      html,
      data: wp,
      csv: [{ name: 'work-precision', header: ['scene', 'curve', 'engine', 'variant', 'setting', 'value', 'error', 'wall_seconds', 'wall_per_sim_second', 'steps'],
        rows: wp.flatMap((s) => s.curves.flatMap((c) => c.points.map((p) => [s.scene, c.label, c.engine, c.variant, c.setting, p.value,
          p.error, p.wall_seconds, p.wall_per_sim_second, p.steps]))) }],
    };
  },
};

function drawable(p) {
  return Number.isFinite(p.error) && p.error > 0 && Number.isFinite(p.wall_per_sim_second) && p.wall_per_sim_second > 0;
}
