// Where, when and why the engines differ on one compared scene (polydyn compare SCENE: divergence.csv,
// impacts.csv, series.csv, friction.csv; method in docs/compare-report.md): one sentence per engine, the
// first divergence with a link into the 3-D replay at that moment, each body's quantities over time (worst
// body first, any body selectable), the impacts matched across engines, the friction cone.
import { esc, num, table } from '../lib/html.mjs';
import { summarize, bodyOrder } from '../lib/differ.mjs';

const MAX_BODIES = 12;   // bodies with curves in the page (the worst first); series.csv has every body
const MAX_IMPACT_ROWS = 30;
const REFERENCE = 'soft reference', CHAOS = 'soft chaos';
const REFERENCE_COLOR = '#222222', CHAOS_COLOR = '#8a8f94';

const runLabel = (ev) => (ev === REFERENCE ? 'reference' : ev === CHAOS ? 'chaos run' : ev);

function lineChart(ctx, { yName, log = false, series, threshold = null }) {
  if (threshold !== null && series.length) {
    series[0].markLine = { silent: true, symbol: 'none', lineStyle: { color: '#a32116', type: 'dashed', width: 1 },
      label: { formatter: `threshold ${threshold}`, position: 'insideEndTop', color: '#a32116' }, data: [{ yAxis: threshold }] };
  }
  return {
    tooltip: { trigger: 'axis', valueFormatter: 'num' },
    legend: { top: 0, type: 'scroll' },
    grid: { left: 64, right: 24, top: 40, bottom: 44 },
    xAxis: { type: 'value', name: 't (s)', nameLocation: 'middle', nameGap: 26 },
    yAxis: { type: log ? 'log' : 'value', scale: !log, name: yName, nameLocation: 'middle', nameGap: 48, axisLabel: { formatter: log ? 'sci' : 'num' } },
    series,
  };
}

function runLine(ctx, ev, points, step = false) {
  const color = ev === REFERENCE ? REFERENCE_COLOR : ev === CHAOS ? CHAOS_COLOR : ctx.color(ev);
  return { name: runLabel(ev), type: 'line', showSymbol: false, connectNulls: false, step: step ? 'end' : false,
    lineStyle: { color, width: ev === REFERENCE ? 2.2 : 1.6, type: ev === CHAOS ? 'dashed' : 'solid' }, itemStyle: { color }, data: points };
}

// The body's curves: one chart option per quantity.
function bodyCharts(ctx, d, body, runs) {
  const of = (ev) => d.series.filter((r) => r.ev === ev && r.body === body);
  const positive = (x) => (x !== null && x > 0 ? x : null);  // a log axis shows no zero
  const err = (key) => runs.filter((ev) => ev !== REFERENCE).map((ev) => runLine(ctx, ev, of(ev).map((r) => [r.t, positive(r[key])])));
  const plain = (key, step = false, evs = runs) => evs.map((ev) => runLine(ctx, ev, of(ev).map((r) => [r.t, r[key]]), step))
    .filter((s) => s.data.some((p) => p[1] !== null));
  const threshold = d.divergence.length ? d.divergence[0].threshold : null;
  return [
    lineChart(ctx, { yName: 'position error (/ size)', log: true, series: err('pos_err'), threshold }),
    lineChart(ctx, { yName: 'rotation error (rad)', log: true, series: err('rot_err_rad'), threshold }),
    lineChart(ctx, { yName: 'energy (J)', series: plain('energy') }),
    lineChart(ctx, { yName: 'largest penetration (/ size)', series: plain('max_penetration_over_size') }),
    lineChart(ctx, { yName: 'contacts', series: plain('contacts', true) }),
    lineChart(ctx, { yName: 'total normal force (N)', series: plain('normal_force') }),
    lineChart(ctx, { yName: 'slip speed of sliding contacts (m/s)', series: plain('slip_speed') }),
  ];
}

function seekLink(t, body, text) {
  return `<a href="#pd-differ-replay" class="pd-seek" data-t="${esc(t)}" data-body="${esc(body)}">${text}</a>`;
}

function impactsTable(d, engines) {
  const ref = d.impacts.filter((r) => r.ev === REFERENCE);
  const byMatch = new Map(engines.map((ev) => [ev, new Map(d.impacts.filter((r) => r.ev === ev && r.reference_impact !== null)
    .map((r) => [r.reference_impact, r]))]));
  const cell = (r) => (r ? { html: `${num(r.restitution)}<br><span class="muted">${num(r.vn_before)} → ${num(r.vn_after)} m/s · ` +
    `Δv<sub>t</sub> ${num(r.tangential_speed_change)}${r.ev === REFERENCE ? '' : ` · at ${num(r.t, 4)} s`}</span>`, cls: 'n' } :
    { html: '<span class="muted">—</span>', cls: 'n', title: 'no impact of these bodies within 0.05 s' });
  const rows = ref.slice(0, MAX_IMPACT_ROWS).map((r) => [{ html: num(r.t, 4), cls: 'n' }, esc(`${r.body_a} – ${r.body_b}`),
    { html: num(r.restitution_requested), cls: 'n' }, cell(r), ...engines.map((ev) => cell(byMatch.get(ev).get(r.impact)))]);
  const unmatched = engines.map((ev) => d.impacts.filter((r) => r.ev === ev && r.reference_impact === null).length);
  rows.push([{ html: 'unmatched', cls: 'muted' }, { html: 'impacts with no counterpart in the reference', cls: 'muted' }, '', '',
    ...unmatched.map((n) => ({ html: String(n), cls: 'n' }))]);
  return `<p>${ref.length} impacts in the reference${ref.length > MAX_IMPACT_ROWS ? ` (the first ${MAX_IMPACT_ROWS} shown; all in impacts.csv)` : ''}. ` +
    'Each cell: restitution e = −v<sub>n</sub> after / v<sub>n</sub> before, the relative normal speeds, the change of the tangential one, ' +
    'and the engine’s time of the same impact (bodies alike, within 0.05 s).</p>' +
    table(['t (s)', 'bodies', 'e requested', 'reference', ...engines.map(esc)], rows, 'impacts');
}

// The ratio's axis ends at twice the largest μ: a contact whose normal force vanishes has any ratio.
function frictionChart(ctx, d, mus) {
  const evs = [...new Set(d.friction.map((r) => r.ev))].filter((ev) => ev !== CHAOS);
  const top = mus.length ? 2 * Math.max(...mus) : 2;
  const series = [];
  let above = 0;
  for (const ev of evs)
    for (const mode of ['slip', 'stick']) {
      const all = d.friction.filter((r) => r.ev === ev && r.mode === mode && r.fn > 0);
      const pts = all.filter((r) => r.ft / r.fn <= top).map((r) => [r.slip_speed, r.ft / r.fn, `${r.body_a}–${r.body_b} ${mode} t=${r.t}`]);
      above += all.length - pts.length;
      if (!pts.length) continue;
      const color = ev === REFERENCE ? REFERENCE_COLOR : ctx.color(ev);
      series.push({ name: `${runLabel(ev)} ${mode}`, type: 'scatter', symbol: mode === 'slip' ? 'circle' : 'triangle', symbolSize: 5,
        itemStyle: { color, opacity: 0.6 }, data: pts });
    }
  if (series.length && mus.length)
    series[0].markLine = { silent: true, symbol: 'none', lineStyle: { color: '#555', type: 'dashed' },
      label: { formatter: '{b}', position: 'insideEndTop' }, data: mus.map((mu) => ({ yAxis: mu, name: `μ ${mu}` })) };
  return { above, top, html: ctx.chart({
    tooltip: { trigger: 'item', formatter: 'point3' }, legend: { top: 0, type: 'scroll' },
    grid: { left: 64, right: 24, top: 40, bottom: 44 },
    xAxis: { type: 'value', name: 'slip speed (m/s)', nameLocation: 'middle', nameGap: 26, axisLabel: { formatter: 'num' } },
    yAxis: { type: 'value', min: 0, max: top, name: '|F_t| / F_n', nameLocation: 'middle', nameGap: 44, axisLabel: { formatter: 'num' } },
    series,
  }, { height: 340 }) };
}

// μ of every pair of material classes the reference used.
function pairMus(ctx) {
  const s = ctx.compareSummary;
  const pairs = s && Array.isArray(s.contact_pairs) ? s.contact_pairs : [];
  return [...new Set(pairs.map((p) => p.mu).filter((mu) => typeof mu === 'number'))].sort((a, b) => a - b);
}

export default {
  id: 'differ',
  title: 'Where, when and why the engines differ',
  inputs: ['divergence.csv', 'impacts.csv', 'series.csv', 'friction.csv', 'compare.json', 'runs/*/'],
  build(ctx) {
    const d = ctx.compareDetail;
    if (!d) return null;
    const s = summarize(d, ctx.metrics ? ctx.metrics.rows : [], pairMus(ctx));
    const runs = [REFERENCE, CHAOS, ...s.engines].filter((ev) => d.series.some((r) => r.ev === ev));
    let html = `<ul class="verdict">${s.sentences.map((x) => `<li>${x.html}</li>`).join('')}</ul>`;

    // first divergence
    html += `<h3>First divergence</h3><p>The first sample at which a body’s position differs from the reference’s by more than ` +
      `${num(s.threshold)} of its size, or its rotation by more than ${num(s.threshold)} rad; “beyond chaos” from the first sample where ` +
      `the error is also more than ${s.chaosFactor}× the chaos run’s (docs/compare-report.md). The time opens the 3-D replay there.</p>`;
    html += table(['engine variant', 'first divergence', 'body', 'error there', 'beyond chaos from', 'verdict'],
      d.divergence.map((r) => [esc(runLabel(r.ev)),
        r.first_t === null ? { html: 'never', cls: 'n' } : { html: seekLink(r.first_t, r.first_body, `${num(r.first_t, 4)} s ▶`), cls: 'n' },
        esc(r.first_body || '—'), { html: r.first_error === null ? '—' : `${num(r.first_error)} (${r.first_kind})`, cls: 'n' },
        { html: r.beyond_chaos_from === null ? '—' : num(r.beyond_chaos_from, 4) + ' s', cls: 'n' }, esc(s.verdictWords[r.verdict])]), 'divergence');

    // replay: the reference solid, every engine overlaid
    const okRuns = ctx.compareRuns.filter((r) => r.ev !== CHAOS);
    html += '<div id="pd-differ-replay">';
    if (!ctx.viewer) {
      html += '<p class="muted">A 3-D replay (the reference with each engine overlaid) is in a report made with the viewer bundle, or: ' +
        `<code>polydyn view ${okRuns.map((r) => esc(r.run_dir)).join(' ')}</code>.</p>`;
    } else {
      const files = okRuns.map((r) => ctx.runData(r.run_dir));
      if (files.length && files.every(Boolean)) {
        html += ctx.replay(okRuns[0].run_dir, `3-D replay: the reference (solid) with ${esc(okRuns.slice(1).map((r) => r.ev).join(', '))} overlaid`,
          { title: `${s.scene}: the reference and ${okRuns.slice(1).map((r) => r.ev).join(', ')}`, runs: files });
      } else {
        html += '<p class="muted">No 3-D replay: a run directory is missing or larger than a replay carries.</p>';
      }
    }
    html += '</div>';

    // over time, per body
    const bodies = bodyOrder(d, s.engines).slice(0, MAX_BODIES);
    if (bodies.length) {
      const options = bodies.map((b) => bodyCharts(ctx, d, b.body, runs));
      const ids = [], empty = [];
      let grid = '';
      for (let q = 0; q < options[0].length; ++q) {
        // a quantity no run reports for any body (no sliding contact, say) gets a word instead of a blank chart
        if (options.every((o) => !o[q].series.some((x) => x.data.some((p) => p[1] !== null)))) {
          empty.push(options[0][q].yAxis.name);
          continue;
        }
        const div = ctx.chart(options[0][q], { height: 260, alternatives: options.map((o) => o[q]) });
        ids.push(/id="([^"]+)"/.exec(div)[1]);
        grid += div;
      }
      html += `<h3>Over time, per body</h3><p>Body <select class="pd-alt" data-charts="${ids.join(' ')}" aria-label="body">` +
        bodies.map((b, i) => `<option value="${i}">${esc(b.body)} (largest error ${num(b.worst)})</option>`).join('') +
        `</select> — the worst first${bodies.length < s.bodyCount ? ` (the ${bodies.length} worst of ${s.bodyCount}; every body is in series.csv)` : ''}. ` +
        'Click a run in a legend to hide it. Dashed grey: the chaos run, the scene’s own divergence. Contacts, forces and slip speeds are those ' +
        'each engine reports at the sample (ODE and Bullet: the contacts of their step that ends there, the force their impulse over it).</p>' +
        `<div class="charts multi">${grid}</div>` +
        (empty.length ? `<p class="muted">Not plotted, no run has any: ${esc(empty.join('; '))}.</p>` : '');
    }

    // impacts
    html += '<h3>Impacts</h3>' + impactsTable(d, s.engines);

    // friction cone
    if (d.friction.some((r) => r.ft > 1e-9 * r.fn)) {  // a flat bounce without friction has nothing to show
      const mus = pairMus(ctx);
      html += '<h3>Friction cone</h3><p>Every contact with a normal force (at most 4 000 per run, evenly taken): |F<sub>t</sub>|/F<sub>n</sub> ' +
        `against the slip speed of its point${mus.length ? `, the pairs’ μ dashed (${mus.join(', ')})` : ''}. A Coulomb cone puts sliding contacts ` +
        'on μ and sticking ones below it at zero slip; a stick that creeps shows slip speed with the ratio below μ. polydyn’s soft engine reports ' +
        'each contact’s mode; ODE’s and Bullet’s contacts count as sliding above 1 mm/s.</p>';
      const cone = frictionChart(ctx, d, mus);
      html += cone.html + (cone.above ? `<p class="muted">${cone.above} contacts with a ratio above ${num(cone.top)} (a normal force near zero) are not drawn; ` +
        'they are in friction.csv.</p>' : '');
    }
    return { html, data: { sentences: s.sentences.map((x) => x.text), divergence: d.divergence }, csv: [] };
  },
};
