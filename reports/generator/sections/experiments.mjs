// One block per experiment: what is expected and why, each run's numbers, the measured quantity over
// time for each engine against the analytic line, and (when a viewer bundle is given) a 3-D replay.
import { esc, num, errText, table, ANALYTIC_COLOR } from '../lib/html.mjs';
import { orderEngineVariants } from '../lib/derive.mjs';

export default {
  id: 'experiments',
  title: 'Experiments',
  inputs: ['results.csv', 'experiments.json', 'series/*.csv', 'runs/*/*/'],
  build(ctx) {
    const exps = ctx.experimentList.filter((e) => (ctx.results && ctx.results.rows.some((r) => r.experiment === e.name)) ||
      (ctx.series && ctx.series.has(e.name)));
    for (const name of ctx.series ? ctx.series.keys() : [])
      if (!exps.some((e) => e.name === name)) exps.push({ name, group: '', title: '', quantity: '', unit: '', meta: null });
    if (!exps.length) return null;
    let html = '';
    const data = [];
    for (const e of exps) {
      const rows = ctx.results ? ctx.results.rows.filter((r) => r.experiment === e.name) : [];
      html += `<article class="experiment" id="exp-${esc(ctx.slug(e.name))}"><h3>${esc(e.name)}${e.title ? ' — ' + esc(e.title) : ''}</h3>`;
      if (e.meta) {
        html += `<dl><dt>expected</dt><dd>${esc(e.meta.formula)}</dd><dt>tolerance</dt><dd>${esc(e.meta.tolerance_reason)}</dd>` +
          `<dt>scene</dt><dd><code>${esc(e.meta.scene)}</code>${e.meta.qualitative ? ' · qualitative check' : ''}</dd></dl>`;
      }
      if (rows.length) {
        const evs = orderEngineVariants(rows).map((x) => x.ev);
        const sorted = [...rows].sort((a, b) => evs.indexOf(a.ev) - evs.indexOf(b.ev) || (a.inputValue ?? 0) - (b.inputValue ?? 0) || a.input.localeCompare(b.input));
        html += table(['engine variant', 'input', `measured${e.unit ? ' (' + esc(e.unit) + ')' : ''}`, 'expected', 'error', 'tolerance', 'status', 'wall (s)', 'note'],
          sorted.map((r) => [esc(r.ev), esc(r.input), { html: num(r.measured, 5), cls: 'n', title: String(r.measured ?? '') },
            { html: num(r.expected, 5), cls: 'n', title: String(r.expected ?? '') },
            { html: errText(r.error, r.relative), cls: 'n', title: String(r.error ?? '') }, { html: errText(r.tolerance, r.relative), cls: 'n' },
            { html: r.status, cls: `st-${r.status}` }, { html: num(r.wall_seconds), cls: 'n' }, esc(r.note)]), 'runs');
      }
      const s = ctx.series && ctx.series.get(e.name);
      if (s) html += seriesCharts(ctx, e, s.points);
      if (ctx.viewer) html += replays(ctx, rows);
      html += '</article>';
      data.push({ name: e.name, rows: rows.map((r) => r.line), series_points: s ? s.points.length : 0 });
    }
    return { html, data, csv: [] };
  },
};

// One chart per input (one chart when the experiment has no varied input): a line per engine-variant
// and the analytic line, dashed.
function seriesCharts(ctx, e, points) {
  const inputs = [...new Set(points.map((p) => p.input))].sort((a, b) => inputNumber(a) - inputNumber(b) || a.localeCompare(b));
  const label = (e.meta && e.meta.series_label) || e.quantity || 'value';
  const allEvs = orderEngineVariants(points.map((p) => ({ ev: `${p.engine} ${p.variant}`, engine: p.engine, variant: p.variant }))).map((x) => x.ev);
  const hasAnalytic = points.some((p) => p.analytic !== null);
  let html = '<div class="keys">' + allEvs.map((ev) => `<span class="key"><i style="background:${ctx.color(ev)}"></i>${esc(ev)}</span>`).join('') +
    (hasAnalytic ? '<span class="key"><i class="dashed"></i>analytic</span>' : '') + '</div>';
  html += `<div class="charts ${inputs.length > 1 ? 'multi' : ''}">`;
  for (const input of inputs) {
    const mine = points.filter((p) => p.input === input);
    const evs = orderEngineVariants(mine.map((p) => ({ ev: `${p.engine} ${p.variant}`, engine: p.engine, variant: p.variant }))).map((x) => x.ev);
    const series = evs.map((ev) => ({
      name: ev, type: 'line', showSymbol: false, sampling: 'lttb', lineStyle: { color: ctx.color(ev), width: 1.8 }, itemStyle: { color: ctx.color(ev) },
      data: mine.filter((p) => `${p.engine} ${p.variant}` === ev && Number.isFinite(p.value)).map((p) => [p.t, p.value]),
    }));
    // the analytic line: from the first run that has one
    const withAnalytic = evs.find((ev) => mine.some((p) => `${p.engine} ${p.variant}` === ev && p.analytic !== null));
    if (withAnalytic) {
      series.push({ name: 'analytic', type: 'line', showSymbol: false, z: 5, lineStyle: { color: ANALYTIC_COLOR, type: 'dashed', width: 1.5 },
        itemStyle: { color: ANALYTIC_COLOR },
        data: mine.filter((p) => `${p.engine} ${p.variant}` === withAnalytic && Number.isFinite(p.analytic)).map((p) => [p.t, p.analytic]) });
    }
    html += '<div class="chartbox">' + ctx.chart({
      title: input ? { text: input, left: 'center', top: 0, textStyle: { fontSize: 13 } } : undefined,
      tooltip: { trigger: 'axis', valueFormatter: 'num' },
      grid: { left: 70, right: 20, top: input ? 30 : 12, bottom: 45 },
      xAxis: { type: 'value', name: 't (s)', nameLocation: 'middle', nameGap: 28 },
      yAxis: { type: 'value', scale: true, name: label + (e.unit && !label.includes('(') ? ` (${e.unit})` : ''), nameLocation: 'middle', nameGap: 52,
        axisLabel: { formatter: 'num' } },
      series,
    }, { height: input ? 270 : 250 }) + '</div>';
  }
  return html + '</div>';
}

function inputNumber(input) {
  const m = /=(.*)$/.exec(input);
  const x = m ? Number(m[1]) : NaN;
  return Number.isFinite(x) ? x : Infinity;
}

// The replay hook: each run with a trajectory gets a <details> that loads its data and mounts the viewer when opened.
function replays(ctx, rows) {
  let html = '';
  for (const r of rows) {
    const run = r.run_dir && ctx.runData(r.run_dir);
    if (!run) continue;
    html += ctx.replay(r.run_dir, `3-D replay: ${esc(r.ev)}${r.input ? ' ' + esc(r.input) : ''}`, run);
  }
  return html;
}
