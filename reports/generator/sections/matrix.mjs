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
        `<div class="muted">${esc(e.quantity)}${e.unit ? ' (' + esc(e.unit) + ')' : ''}</div>`, cls: 'exp' }];
      for (const ev of m.engine_variants) {
        const c = m.cells.find((x) => x.experiment === e.name && x.ev === ev);
        if (!c) { row.push({ html: '<span class="muted">not run</span>', cls: 'cell none' }); continue; }
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
      '<span class="st-NOT_BUILT">NOT_BUILT</span> engine not in this build. Error: |measured − expected| (relative ones in %); ' +
      '"× tol" is error ÷ tolerance (below 1 passes). A cell over several inputs shows the worst status, how many inputs pass and the largest error. Hover a cell for exact values.</p>';
    return {
      html,
      data: m,
      csv: [{ name: 'matrix', header: ['experiment', 'engine', 'variant', 'status', 'inputs', 'passed', 'error', 'tolerance', 'relative',
        'error_over_tolerance', 'worst_input', 'wall_seconds'],
      rows: m.cells.map((c) => [c.experiment, c.engine, c.variant, c.status, c.inputs, c.passed, c.error, c.tolerance, c.relative ? 'yes' : 'no',
        c.error_over_tolerance, c.worst_input, c.wall_seconds]) }],
    };
  },
};
