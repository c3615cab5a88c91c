// Restitution: requested e, the model's prediction, and what each engine measured.
import { esc, num, table, ANALYTIC_COLOR } from '../lib/html.mjs';

export default {
  id: 'restitution',
  title: 'Restitution',
  inputs: ['results.csv'],
  build(ctx) {
    const r = ctx.restitution;
    if (!r) return null;
    r.rows.sort((a, b) => order(ctx, a.experiment) - order(ctx, b.experiment) || (a.requested ?? Infinity) - (b.requested ?? Infinity) || a.input.localeCompare(b.input));
    const header = ['experiment', 'requested e', 'predicted e', ...r.engine_variants.map((ev) => `${esc(ev)} measured`)];
    const rows = r.rows.map((g) => [
      `<a href="#exp-${esc(ctx.slug(g.experiment))}">${esc(g.experiment)}</a> <span class="title">${esc(title(ctx, g.experiment))}</span>${g.requested === null && g.input ? ' <span class="muted">' + esc(g.input) + '</span>' : ''}`,
      { html: num(g.requested), cls: 'n' },
      { html: num(g.predicted, 4), cls: 'n', title: String(g.predicted ?? '') },
      ...r.engine_variants.map((ev) => g.status[ev] === undefined ? { html: '—', cls: 'n muted' }
        : { html: num(g.measured[ev], 4) + (g.predicted !== null && Number.isFinite(g.measured[ev]) ? ` <span class="muted">(${signed(g.measured[ev] - g.predicted)})</span>` : ''),
          cls: `n st-${g.status[ev]}`, title: `${ev}: ${g.measured[ev]} (${g.status[ev]})` }),
    ]);
    let html = '<p>The model predicts the restitution from the damping ratio of the contacts that act at once and the effective mass ' +
      '(catalogue A1, A2): it is not the requested e unless one vertex hits at the body’s own mass. In brackets: measured − predicted; colour: PASS/FAIL of that run.</p>';
    html += table(header, rows, 'restitution');
    const withReq = r.rows.filter((g) => g.requested !== null);
    if (withReq.length) {
      const series = r.engine_variants.map((ev) => ({
        name: ev, type: 'scatter', symbolSize: 10, itemStyle: { color: ctx.color(ev) },
        data: withReq.filter((g) => Number.isFinite(g.measured[ev])).map((g) => [g.requested, g.measured[ev], g.experiment]),
      }));
      const pred = withReq.filter((g) => g.predicted !== null).map((g) => [g.requested, g.predicted, g.experiment]);
      series.push({ name: 'predicted', type: 'scatter', symbol: 'diamond', symbolSize: 14,
        itemStyle: { color: 'rgba(0,0,0,0)', borderColor: ANALYTIC_COLOR, borderWidth: 1.5 }, data: pred, z: 1 });
      series.push({ name: 'measured = requested', type: 'line', showSymbol: false, lineStyle: { type: 'dotted', color: '#999' },
        data: [[0, 0], [1, 1]], silent: true });
      html += ctx.chart({
        tooltip: { trigger: 'item', formatter: 'point3' },
        legend: { top: 0 },
        grid: { left: 60, right: 20, top: 40, bottom: 50 },
        xAxis: { type: 'value', name: 'requested e', nameLocation: 'middle', nameGap: 30, min: 0, max: 1 },
        yAxis: { type: 'value', name: 'measured e', nameLocation: 'middle', nameGap: 40, min: 0, max: 1 },
        series,
      }, { height: 360, width: 560 });
    }
    return {
      html,
      data: r,
      csv: [{ name: 'restitution', header: ['experiment', 'input', 'requested', 'predicted', 'engine', 'variant', 'measured', 'status'],
        rows: r.rows.flatMap((g) => r.engine_variants.filter((ev) => g.status[ev] !== undefined)
          .map((ev) => [g.experiment, g.input, g.requested, g.predicted, ...ev.split(' '), g.measured[ev], g.status[ev]])) }],
    };
  },
};

function title(ctx, name) {
  const e = ctx.experimentList.find((x) => x.name === name);
  return e ? e.title : '';
}

function order(ctx, name) {
  const k = ctx.experimentList.findIndex((e) => e.name === name);
  return k < 0 ? Infinity : k;
}

function signed(x) {
  return (x >= 0 ? '+' : '−') + num(Math.abs(x), 2);
}
