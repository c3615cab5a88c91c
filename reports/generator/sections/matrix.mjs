// PASS/FAIL matrix: experiment × engine-variant, the error in each cell.
import { esc, num, errText, table } from '../lib/html.mjs';

export default {
  id: 'matrix',
  title: 'PASS/FAIL matrix',
  inputs: ['results.csv'],
  build(ctx) {
    const m = ctx.matrix;
    if (!m) return null;
    const exps = ctx.experimentList.filter((e) => m.experiments.includes(e.name));
    const rows = [];
    let group = null;
    for (const e of exps) {
      if (e.group !== group) {
        group = e.group;
        rows.push([{ html: `Group ${esc(group)}${ctx.groupNames[group] ? ' — ' + esc(ctx.groupNames[group]) : ''}`, cls: 'group', attrs: ` colspan="${m.engine_variants.length + 1}"` }]);
      }
      const row = [{ html: `<a href="#exp-${esc(ctx.slug(e.name))}">${esc(e.name)}</a> <span class="title">${esc(e.title)}</span>` +
        `<div class="muted">${esc(e.quantity)}${e.unit ? ' (' + esc(e.unit) + ')' : ''} · ${kindText(e)}</div>`, cls: 'exp' }];
      for (const ev of m.engine_variants) {
        const c = m.cells.find((x) => x.experiment === e.name && x.ev === ev);
        if (!c) { row.push({ html: '<span class="muted">not run</span>', cls: 'cell none' }); continue; }
        if (c.status === 'NOT_APPLICABLE') {
          // measured but not judged: the prediction is the soft model's, not a law this variant must obey
          row.push({
            html: '<span class="st">n/a</span>' + (c.error !== null ? `<div class="err muted">error ${errText(c.error, c.relative)}, not judged</div>` : ''),
            cls: 'cell st-NOT_APPLICABLE',
            title: `${e.name} · ${ev}: not applicable — ${c.not_applicable_reason}` + (c.error !== null ? `\nerror ${c.error}${c.relative ? ' (relative)' : ''} (not judged)` : ''),
            attrs: ` data-experiment="${esc(e.name)}" data-ev="${esc(ev)}" data-status="${c.status}" data-error="${c.error === null ? '' : esc(String(c.error))}"` +
              ` data-reason="${esc(c.not_applicable_reason)}"`,
          });
          continue;
        }
        const count = c.inputs > 1 ? ` <span class="count">${c.passed}/${c.inputs}</span>` : '';
        const err = c.error !== null ? `<div class="err">error ${errText(c.error, c.relative)}</div>` : '<div class="err muted">no error</div>';
        const tol = c.error_over_tolerance !== null ? `<div class="ratio">${num(c.error_over_tolerance)}× tol</div>` : '';
        row.push({
          html: `<span class="st">${c.status}</span>${count}${err}${tol}`,
          cls: `cell st-${c.status}`,
          title: `${e.name} · ${ev}: ${c.status}` + (c.error !== null ? `\nerror ${c.error}${c.relative ? ' (relative)' : ''}` : '') +
            (c.tolerance !== null ? `\ntolerance ${c.tolerance}` : '') + (c.worst_input ? `\nlargest at ${c.worst_input}` : '') +
            (c.inputs > 1 ? `\n${c.passed} of ${c.inputs} inputs pass` : ''),
          attrs: ` data-experiment="${esc(e.name)}" data-ev="${esc(ev)}" data-status="${c.status}" data-error="${c.error === null ? '' : esc(String(c.error))}"`,
        });
      }
      rows.push(row);
    }
    const html = table(['experiment', ...m.engine_variants.map(esc)], rows, 'matrix') +
      '<p class="legend"><span class="st-PASS">PASS</span> within tolerance · <span class="st-FAIL">FAIL</span> outside · ' +
      '<span class="st-ERROR">ERROR</span> the run failed · <span class="st-REFUSED">REFUSED</span> the engine cannot run the scene as written · ' +
      '<span class="st-NOT_BUILT">NOT_BUILT</span> engine not in this build · <span class="st-NOT_APPLICABLE">n/a</span> a prediction of the ' +
      'soft model on a variant that does not have that model: measured, not judged (hover for the reason). A <i>law</i> is judged on every ' +
      'engine; a <i>model prediction</i> only on the soft engine and the variants whose matched constants make it theirs. Error: |measured − expected| (relative ones in %); ' +
      '"× tol" is error ÷ tolerance (below 1 passes). A cell over several inputs shows the worst status, how many inputs pass and the largest error. Hover a cell for exact values.</p>';
    return {
      html,
      data: m,
      csv: [{ name: 'matrix', header: ['experiment', 'engine', 'variant', 'status', 'inputs', 'passed', 'error', 'tolerance', 'relative',
        'error_over_tolerance', 'worst_input', 'wall_seconds', 'not_applicable_reason'],
      rows: m.cells.map((c) => [c.experiment, c.engine, c.variant, c.status, c.inputs, c.passed, c.error, c.tolerance, c.relative ? 'yes' : 'no',
        c.error_over_tolerance, c.worst_input, c.wall_seconds, c.not_applicable_reason ?? '']) }],
    };
  },
};

// "law" or "model prediction" (experiments.json's kind; an experiment without one is a law)
function kindText(e) {
  return e.meta && e.meta.kind === 'model_prediction' ? 'model prediction' : 'law';
}
