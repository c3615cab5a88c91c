// The one-screen summary that opens the report: per engine-variant the experiments passed, the
// median error over tolerance at its default setting, the cost to reach each experiment's tolerance, and one
// diagram of every engine-variant's front (median error/tolerance against median cost over the knob's settings).
import { esc, num, table } from '../lib/html.mjs';
import { median, ratio } from '../lib/derive.mjs';
import { logLogLine, logLogOption } from '../lib/charts.mjs';

export default {
  id: 'summary',
  title: 'Summary',
  inputs: ['results.csv', 'precision.csv'],
  build(ctx) {
    const v = ctx.verdicts;
    const pr = ctx.precision;
    if (!v && !pr) return null;
    const evs = ctx.evOrder.filter((ev) => (v && v.some((x) => x.ev === ev)) || (pr && pr.summary.some((x) => x.ev === ev)));
    const rows = evs.map((ev) => {
      const verdict = v ? v.find((x) => x.ev === ev) : null;
      const judgedRows = ctx.results ? ctx.results.rows.filter((r) => r.ev === ev && (r.status === 'PASS' || r.status === 'FAIL')) : [];
      const s = pr ? pr.summary.find((x) => x.ev === ev) : null;
      return {
        ev,
        pass: verdict ? verdict.pass : null,
        experiments: verdict ? verdict.experiments : null,
        median_error_over_tolerance: median(judgedRows.map(ratio)),
        reached: s ? s.reached : null,
        judged: s ? s.judged : null,
        median_cost_to_tolerance: s ? s.median_cost_to_tolerance : null,
        never: s ? s.never : [],
        not_built: s ? s.not_built : false,
      };
    });
    const header = ['engine variant', 'experiments passed (default setting)', 'median error / tolerance (default setting)',
      'experiments whose tolerance some setting reaches', 'median cost to reach the tolerance (s per simulated s)'];
    let html = table(header, rows.map((r) => [
      { html: `<span class="swatch" style="background:${ctx.color(r.ev)}"></span>${esc(r.ev)}` },
      { html: r.pass === null ? '—' : `${r.pass} / ${r.experiments}`, cls: 'n' + (r.pass !== null && r.pass < r.experiments ? ' bad' : '') },
      { html: num(r.median_error_over_tolerance), cls: 'n' + (r.median_error_over_tolerance > 1 ? ' bad' : '') },
      { html: r.not_built ? 'not built' : r.reached === null ? '—' : `${r.reached} / ${r.judged}`, cls: 'n',
        title: r.never.length ? `never: ${r.never.join(', ')}` : '' },
      { html: num(r.median_cost_to_tolerance), cls: 'n' },
    ]), 'summary-table');
    html += '<p class="legend">Default setting: the Gedanken suite’s runs (soft: the scene’s tolerance; ODE and Bullet: a 1 ms step). ' +
      'Each engine is judged against the closed form of every experiment that applies to it (predictions of the soft model are not applicable ' +
      'to the rigid variants). The cost is read on the work-precision curves below (Work-precision against the closed form) over the experiments ' +
      'the engine reaches; the ones it never reaches are listed on hover.</p>';
    if (pr) {
      const series = pr.summary.filter((s) => s.front.length).map((s) => logLogLine(s.ev, ctx.color(s.ev),
        s.front.map((f) => [f.median_wall_per_sim_second, f.median_error_over_tolerance, `${s.setting}=${f.value} (${f.experiments} experiments)`]),
        s.ev === 'soft fixed' ? 'dashed' : 'solid'));
      html += '<div class="charts"><div class="chartbox wide"><h3>The engines’ fronts</h3>' +
        '<p class="muted">At each setting of an engine’s knob (loosest on the left), the median over the experiments of error / tolerance ' +
        'against the median wall time per simulated second. Below the dashed line the typical experiment is within its tolerance.</p>';
      html += ctx.chart(logLogOption({ xName: 'median wall time per simulated second (s/s)', yName: 'median error / tolerance', series,
        guide: { value: 1, label: 'error = tolerance' }, right: 110 }), { height: 340 });
      html += '</div></div>';
    }
    return {
      html,
      data: { engine_variants: rows, fronts: pr ? pr.summary.map((s) => ({ ev: s.ev, setting: s.setting, front: s.front })) : [] },
      csv: [{ name: 'summary', header: ['engine', 'variant', 'pass', 'experiments', 'median_error_over_tolerance', 'reached', 'judged',
        'median_cost_to_tolerance', 'never'],
      rows: rows.map((r) => [...r.ev.split(' '), r.pass, r.experiments, r.median_error_over_tolerance, r.reached, r.judged,
        r.median_cost_to_tolerance, r.never.join(';')]) }],
    };
  },
};
