// Cube tosses and planar drops against reality (polydyn cubetoss): per engine and parameter set, the end
// and RMS errors (and, for the drops, the first bounce) on the runs not used for fitting, their
// distribution, the fitted parameters, and one typical run — its errors over time and, with a viewer
// bundle, a 3-D replay of the record with every engine's run overlaid. The same section serves both data
// sets (realData below); the "noise" engine's rows are the record one sample late, the floor.
import { esc, num, table, ANALYTIC_COLOR } from '../lib/html.mjs';
import { orderEngineVariants } from '../lib/derive.mjs';
import { DEG, headlineSplit, paramsOrder, errorsOverTime, ecdf } from '../lib/cubetoss.mjs';

const QUANTITIES = ['pos_err_end', 'rot_err_end', 'pos_err_rms', 'rot_err_rms', 'wall_seconds', 'cpu_seconds', 'impact1_dv'];
const RECORD_COLOR = ANALYTIC_COLOR;

// The words of each data set.
function wordsOf(ct) {
  return ct.planar
    ? { noun: 'drop', nouns: 'drops', unit: 'side lengths', what: 'the block',
      intro: 'Real drops of a square block (side 0.06 m) bouncing in a vertical plane onto a flat surface, recorded at 250 Hz ' +
        '(Fazeli et al. 2017; the data of DAIRLab/ImpactModeling), each simulated with the block held in the x–z plane ' +
        '(scene <code>planar</code>) from its first recorded pose and velocity to its last sample, then compared with the record: ' +
        'the distance between the simulated and the recorded centre in side lengths, the angle between the two orientations, at the ' +
        'end of the drop and as RMS over it, and the first bounce (the centre’s velocity after it against the record’s). ' }
    : { noun: 'toss', nouns: 'tosses', unit: 'cube widths', what: 'the cube',
      intro: 'Real tosses of a wooden cube onto a board, recorded at 148 Hz, each simulated from its first recorded pose and ' +
        'velocity to its last sample, then compared with the record: the distance between the simulated and the recorded centre in ' +
        'cube widths, and the angle between the two orientations, at the end of the toss and as RMS over it. ' };
}

function realData({ id, title, key, typicalKey, dirName }) {
  return {
    id,
    title,
    inputs: [`${dirName}/summary.csv`, `${dirName}/per_toss.csv`, `${dirName}/fit.csv`, `${dirName}/replay/TOSS/*/`],
    build: (ctx) => build(ctx, ctx[key], ctx[typicalKey], id),
  };
}

export default realData({ id: 'cubetoss', title: 'Cube tosses against reality', key: 'cubetoss', typicalKey: 'cubetossTypical',
  dirName: 'cubetoss' });
export const planarDrops = realData({ id: 'planar-drops', title: 'Planar drops against reality', key: 'planarDrops',
  typicalKey: 'planarDropsTypical', dirName: 'planar-drops' });

function build(ctx, ct, typical, id) {
  if (!ct) return null;
  const w = wordsOf(ct);
  const split = headlineSplit(ct.summary);
  const evs = orderEngineVariants(ct.summary).map((x) => x.ev);
  const params = paramsOrder(ct.summary);
  const where = ct.at === '.' ? 'this directory' : `<code>${esc(ct.at)}/</code>`;

  // the headline: one row per engine-variant and parameter set at the split
  const headline = [];
  for (const ev of evs) {
    for (const p of params) {
      const of = (q) => ct.summary.find((r) => r.ev === ev && r.params === p && r.split === split && r.quantity === q);
      const first = QUANTITIES.map(of).find(Boolean);
      if (!first) continue;
      const row = { engine: first.engine, variant: first.variant, ev, params: p, split, status: first.status, tosses: first.tosses,
        completed: first.completed };
      for (const q of QUANTITIES) {
        const r = of(q);
        row[q] = r ? { mean: r.mean, median: r.median, p90: r.p90 } : { mean: null, median: null, p90: null };
      }
      headline.push(row);
    }
  }
  const prov = ct.provenance;
  let html = '<p>' + w.intro +
    `Shown: the ${split === 'test' ? `test ${w.nouns}, which no fit has seen` : w.nouns}; median and 90th percentile over them. ` +
    `Wall and CPU time are the mean per ${w.noun} (one ${w.noun} is one process’s work). The <code>noise shift1</code> rows are ` +
    'the record one sample late, judged like a run: the floor that sampling and tracking set.</p>';
  html += `<p class="muted">From ${where}${ct.readme ? ' (its README.md has the full tables)' : ''}` +
    (prov.command ? `; command <code>${esc(prov.command)}</code>` : '') + (prov.commit ? `, commit ${esc(prov.commit)}` : '') +
    (prov.data ? `; data ${esc(prov.data)}` : '') + (prov.machine ? `; machine ${esc(prov.machine)}` : '') + '.' +
    (prov.fit ? ` Fit: ${esc(prov.fit)}.` : '') + '</p>';
  const d = (x) => (x === null ? null : x * DEG);
  html += table(['engine variant', 'parameters', 'completed', 'position end median', 'position end p90', 'rotation end median (°)',
    'rotation end p90 (°)', 'position RMS median', 'rotation RMS median (°)', ...(ct.planar ? ['first bounce Δv median (m/s)',
      'first bounce Δv p90 (m/s)'] : []), `wall per ${w.noun} (s)`, `CPU per ${w.noun} (s)`],
  headline.map((r) => [
    `<span class="key"><i style="background:${ctx.color(r.ev)}"></i>${esc(r.ev)}</span>`, esc(r.params),
    { html: `${r.completed}/${r.tosses}`, cls: `n${r.completed < r.tosses ? ' bad' : ''}`, title: r.status },
    { html: num(r.pos_err_end.median), cls: 'n', title: String(r.pos_err_end.median ?? '') },
    { html: num(r.pos_err_end.p90), cls: 'n', title: String(r.pos_err_end.p90 ?? '') },
    { html: num(d(r.rot_err_end.median)), cls: 'n', title: String(r.rot_err_end.median ?? '') + ' rad' },
    { html: num(d(r.rot_err_end.p90)), cls: 'n', title: String(r.rot_err_end.p90 ?? '') + ' rad' },
    { html: num(r.pos_err_rms.median), cls: 'n' }, { html: num(d(r.rot_err_rms.median)), cls: 'n' },
    ...(ct.planar ? [{ html: num(r.impact1_dv.median), cls: 'n' }, { html: num(r.impact1_dv.p90), cls: 'n' }] : []),
    { html: num(r.wall_seconds.mean), cls: 'n' }, { html: num(r.cpu_seconds.mean), cls: 'n' },
  ]), id);
  html += `<p class="muted">Positions in ${w.unit}. Parameter sets other than <code>default</code> and <code>fitted</code> are ` +
    'diagnostics of the same fitted parameters (e.g. a tighter tolerance: the integration error’s share; the uniform cube’s inertia).</p>';

  if (ct.perToss) html += distributions(ctx, ct.perToss, split, evs, w, ct.planar);
  if (ct.fit && ct.fit.length) html += fitTable(ctx, ct.fit, w, ct.planar, id);
  const typ = typical ? typicalBlock(ctx, ct, typical, w, id) : null;
  if (typ) html += typ.html;

  return {
    html,
    data: { directory: ct.at, split, provenance: prov, headline, fit: ct.fit ? ct.fit.map(({ line, ev, ...f }) => f) : null,
      typical: typ ? typ.data : null },
    csv: [{ name: id, header: ['engine', 'variant', 'params', 'split', 'completed', 'tosses', 'pos_err_end_median',
      'pos_err_end_p90', 'rot_err_end_median_rad', 'rot_err_end_p90_rad', 'pos_err_rms_median', 'rot_err_rms_median_rad',
      'wall_seconds_mean', 'cpu_seconds_mean'],
    rows: headline.map((r) => [r.engine, r.variant, r.params, r.split, r.completed, r.tosses, r.pos_err_end.median, r.pos_err_end.p90,
      r.rot_err_end.median, r.rot_err_end.p90, r.pos_err_rms.median, r.rot_err_rms.median, r.wall_seconds.mean, r.cpu_seconds.mean]) },
    ...(typ ? typ.csv : [])],
  };
}

// The distribution of the end errors over the tosses: one line per engine-variant, solid for the
// default parameters and dashed for the fitted ones (other parameter sets are left out here).
function distributions(ctx, perToss, split, evs, w, planar) {
  const rows = perToss.filter((r) => r.status === 'ok' && (split === 'all' || r.split === split));
  const sets = paramsOrder(rows).filter((p) => p === 'default' || p === 'fitted');
  if (!sets.length) return '';
  const chart = (field, scale, name) => {
    const series = [];
    for (const ev of evs) {
      for (const p of sets) {
        const data = ecdf(rows.filter((r) => r.ev === ev && r.params === p).map((r) => r[field] * scale)).map(([x, y]) => [x, y, p]);
        if (!data.length) continue;
        series.push({ name: `${ev} ${p}`, type: 'line', step: 'end', showSymbol: false,
          lineStyle: { color: ctx.color(ev), width: 1.6, type: p === 'fitted' ? 'dashed' : 'solid' }, itemStyle: { color: ctx.color(ev) }, data });
      }
    }
    return '<div class="chartbox">' + ctx.chart({
      tooltip: { trigger: 'item', formatter: 'point3' },
      grid: { left: 60, right: 20, top: 12, bottom: 45 },
      xAxis: { type: 'value', name, nameLocation: 'middle', nameGap: 28, min: 0, axisLabel: { formatter: 'num' } },
      yAxis: { type: 'value', name: `fraction of ${w.nouns}`, nameLocation: 'middle', nameGap: 42, min: 0, max: 1 },
      series,
    }, { height: 320 }) + '</div>';
  };
  const keys = '<div class="keys">' + evs.filter((ev) => rows.some((r) => r.ev === ev))
    .map((ev) => `<span class="key"><i style="background:${ctx.color(ev)}"></i>${esc(ev)}</span>`).join('') +
    (sets.length > 1 ? '<span class="key"><i style="background:#222"></i>solid: default</span><span class="key"><i class="dashed"></i>dashed: fitted</span>' : '') + '</div>';
  return `<h3>Distribution over the ${split === 'test' ? 'test ' : ''}${w.nouns}</h3>` +
    `<p>The fraction of ${w.nouns} whose error is at most x${sets.length > 1 ? ' (solid: default parameters; dashed: fitted)' : ''}. ` +
    'A curve further up and to the left is closer to reality.</p>' + keys +
    '<div class="charts multi">' + chart('pos_err_end', 1, `end position error (${w.unit})`) + chart('rot_err_end_rad', DEG, 'end rotation error (°)') +
    (planar ? chart('impact1_dv', 1, 'first-bounce velocity error (m/s)') : '') + '</div>';
}

function fitTable(ctx, fit, w, planar, id) {
  const rows = fit.filter((f) => f.status !== 'no parameters').map((f) => [
    `<span class="key"><i style="background:${ctx.color(f.ev)}"></i>${esc(f.ev)}</span>`,
    f.status === 'ok' ? esc(f.fitted.join(', ')) : { html: 'not built', cls: 'muted' },
    { html: `${num(f.start_mu, 4)} → ${num(f.mu, 4)}`, cls: 'n' },
    { html: `${num(f.start_restitution, 4)} → ${num(f.restitution, 4)}`, cls: 'n' },
    { html: f.fitted.includes('kn') ? `${num(f.start_kn)} → ${num(f.kn)}` : `${num(f.kn)} (as given)`, cls: 'n' },
    { html: `${num(f.start_objective_train, 4)} → ${num(f.objective_train, 4)}`, cls: 'n' },
    { html: f.evaluations === null ? '—' : String(f.evaluations), cls: 'n' },
    f.converged === null ? '—' : f.converged ? 'yes' : 'no (stopped at the evaluation limit)',
    { html: `${f.train_tosses ?? '—'}${f.train_every > 1 ? ` (every ${f.train_every}-th)` : ''} / ${f.test_tosses ?? '—'}`, cls: 'n' },
  ]);
  return `<h3>Fitted parameters</h3><p>A derivative-free fit (Nelder–Mead) of each engine’s free parameters on the training ${w.nouns}; ` +
    `objective: mean end position error (${w.unit}) + mean end rotation error (rad)${planar ? ' + mean first-bounce velocity error (m/s)' : ''} ` +
    'over them. k_n is each side’s normal stiffness.</p>' +
    table(['engine variant', 'fitted', 'μ', 'e', 'k_n (N/m)', 'objective (training)', 'evaluations', 'converged', `${w.nouns} fitted on / tested on`],
      rows, `${id}-fit`);
}

// The typical toss: its errors per engine, the centre's height and the errors over time, the replay.
function typicalBlock(ctx, ct, typ, w, id) {
  const rows = ct.perToss.filter((r) => r.toss === typ.toss && r.params === typ.params);
  let html = `<h3>A typical ${w.noun}: ${typ.split === 'test' ? 'test ' : ''}${w.noun} ${typ.toss}</h3>` +
    `<p>Of the ${typ.tosses} ${typ.split === 'test' ? 'test ' : ''}${w.nouns} ${esc(typ.ev)} completed with the ${esc(typ.params)} parameters, ` +
    `${w.noun} ${typ.toss} has the end position error nearest their median (${num(typ.pos_err_end)} against ${num(typ.median)} ${w.unit})` +
    `${typ.replay ? `, among the ${w.nouns} whose run directories are kept` : ''}. Each engine with the ${esc(typ.params)} parameters:</p>`;
  html += table(['engine variant', 'position end', 'position RMS', 'rotation end (°)', 'rotation RMS (°)', 'wall (s)', 'steps'],
    rows.map((r) => [`<span class="key"><i style="background:${ctx.color(r.ev)}"></i>${esc(r.ev)}</span>`,
      { html: num(r.pos_err_end), cls: 'n' }, { html: num(r.pos_err_rms), cls: 'n' },
      { html: num(r.rot_err_end_rad === null ? null : r.rot_err_end_rad * DEG), cls: 'n' },
      { html: num(r.rot_err_rms_rad === null ? null : r.rot_err_rms_rad * DEG), cls: 'n' },
      { html: num(r.wall_seconds), cls: 'n' }, { html: r.steps === null ? '—' : String(r.steps), cls: 'n' }]), `${id}-typical`);
  const data = { toss: typ.toss, params: typ.params, split: typ.split, median: typ.median, pos_err_end: typ.pos_err_end,
    runs: [] };
  const csvRows = [];
  if (!typ.runs.length) {
    html += `<p class="muted">No run directories of this ${w.noun} are there (polydyn cubetoss --no-runs), so no motion is shown.</p>`;
    return { html, data, csv: [] };
  }
  const record = typ.runs[0];
  const color = (run) => (run.ev ? ctx.color(run.ev) : RECORD_COLOR);
  const over = typ.runs.slice(1).map((run) => ({ run, errors: errorsOverTime(record.samples, run.samples, typ.width) }));
  for (const { run, errors } of over) {
    const last = errors[errors.length - 1];
    data.runs.push({ label: run.label, run_dir: run.run_dir, samples: errors.length,
      pos_err_end: last ? last.pos : null, rot_err_end_rad: last ? last.rot : null });
    for (const e of errors) csvRows.push([typ.toss, ...run.ev.split(' '), e.t, e.pos, e.rot]);
  }
  const line = (run, points) => ({ name: run.label, type: 'line', showSymbol: false,
    lineStyle: { color: color(run), width: run.ev ? 1.6 : 2.4 }, itemStyle: { color: color(run) },
    z: run.ev ? 2 : 3, data: points });
  const chart = (series, name) => '<div class="chartbox">' + ctx.chart({
    tooltip: { trigger: 'axis', valueFormatter: 'num' },
    legend: { top: 0 },
    grid: { left: 60, right: 20, top: 36, bottom: 45 },
    xAxis: { type: 'value', name: 't (s)', nameLocation: 'middle', nameGap: 28 },
    yAxis: { type: 'value', scale: true, name, nameLocation: 'middle', nameGap: 44, axisLabel: { formatter: 'num' } },
    series,
  }, { height: 280 }) + '</div>';
  html += `<p>The height of ${w.what}’s centre (black: the record), and each engine’s distance from the record (${w.unit} of ${num(typ.width, 4)} m) ` +
    `and rotation from it over the ${w.noun}.</p><div class="charts multi">` +
    chart(typ.runs.map((run) => line(run, run.samples.map((s) => [s.t, s.x[2]]))), 'height of the centre (m)') +
    chart(over.map(({ run, errors }) => line(run, errors.map((e) => [e.t, e.pos]))), `position error (${w.unit})`) +
    chart(over.map(({ run, errors }) => line(run, errors.map((e) => [e.t, e.rot * DEG]))), 'rotation error (°)') + '</div>';
  if (typ.missing.length) html += `<p class="muted">No run directory for ${esc(typ.missing.join(', '))}.</p>`;
  if (!ctx.viewer) {
    html += `<p class="muted">A 3-D replay of this ${w.noun} (the record with each engine’s run overlaid) is in a report made with the viewer ` +
      '(<code>scripts/gedanken-report</code> writes one to <code>out/gedanken/report.html</code>), or: <code>polydyn view</code> on the run directories.</p>';
  } else {
    const files = typ.runs.map((run) => ctx.runData(run.run_dir));
    if (files.every(Boolean)) {
      const payload = { title: `${w.noun} ${typ.toss}: the record and ${typ.runs.slice(1).map((r) => r.label).join(', ')}`, runs: files };
      html += ctx.replay(typ.runs[0].run_dir, `3-D replay: the record of ${w.noun} ${typ.toss} ` +
        `(solid) with ${esc(typ.runs.slice(1).map((r) => r.label).join(', '))} overlaid`, payload);
    }
  }
  return { html, data, csv: [{ name: `${id}-typical`, header: ['toss', 'engine', 'variant', 't', 'pos_err', 'rot_err_rad'], rows: csvRows }] };
}
