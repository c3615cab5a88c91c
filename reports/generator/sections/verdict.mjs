// Verdict: who is right, by how much, and at what cost — in a few sentences and one table.
import { esc, num, table } from '../lib/html.mjs';

export default {
  id: 'verdict',
  title: 'Verdict',
  inputs: ['results.csv', 'sweep.csv'],
  build(ctx) {
    const v = ctx.verdicts;
    const costs = ctx.cost;
    if (!v && !costs) return null;
    const sentences = [];
    for (const x of v || []) {
      let s = `<b>${esc(x.ev)}</b> passes ${x.pass} of the ${x.experiments} experiment${x.experiments === 1 ? '' : 's'} that apply to it`;
      if (x.not_applicable.length) s += ` (${x.not_applicable.length} prediction${x.not_applicable.length === 1 ? '' : 's'} of the soft model not applicable: ${esc(x.not_applicable.join(', '))})`;
      const parts = [];
      if (x.fail.length) parts.push(`fails ${esc(x.fail.join(', '))}`);
      if (x.error.length) parts.push(`stopped with an error in ${esc(x.error.join(', '))}`);
      if (x.refused.length) parts.push(`refused ${esc(x.refused.join(', '))}`);
      if (x.not_built.length) parts.push(`was not built for ${esc(x.not_built.join(', '))}`);
      if (parts.length) s += '; ' + parts.join('; ');
      if (x.worst) s += `; its largest error is ${num(x.worst.error_over_tolerance)}× the tolerance (${esc(x.worst.experiment)}${x.worst.input ? ' ' + esc(x.worst.input) : ''})`;
      if (x.total_wall_seconds !== null) s += `; ${num(x.total_wall_seconds)} s of wall time in all`;
      sentences.push(s + '.');
    }
    if (costs && costs.scenes.length) {
      for (const scene of costs.scenes) {
        const reach = costs.rows.filter((r) => r.to_target[scene] && r.to_target[scene].kind !== 'never')
          .sort((a, b) => a.to_target[scene].wall_per_sim_second - b.to_target[scene].wall_per_sim_second);
        const never = costs.rows.filter((r) => r.to_target[scene] && r.to_target[scene].kind === 'never');
        let s = `To reach ${costs.self_convergence[scene] ? 'a self-convergence error (against its own finest run)' : 'an error'} of ${num(costs.target)} on <b>${esc(scene)}</b>, `;
        s += reach.length
          ? reach.map((r) => `${esc(r.ev)} needs ${r.to_target[scene].kind === 'at_most' ? 'at most ' : ''}${num(r.to_target[scene].wall_per_sim_second)} s per simulated second`).join(', ')
          : 'no engine gets there';
        if (never.length) s += `; ${esc(never.map((r) => r.ev).join(', '))} never ${never.length === 1 ? 'does' : 'do'} at the settings swept`;
        sentences.push(s + '.');
      }
    }
    let html = `<ul class="verdict">${sentences.map((s) => `<li>${s}</li>`).join('\n')}</ul>`;
    html += '<p class="note">ODE and Bullet solve a different (rigid, LCP) contact model: every engine is judged against ' +
      'the analytic answer of each experiment, never against polydyn’s own runs.</p>';
    if (v) {
      html += table(['engine variant', 'PASS (of the experiments that apply)', 'FAIL', 'other', 'largest error / tolerance', 'wall time, total (s)', 'wall time, median per experiment (s)'],
        v.map((x) => [
          esc(x.ev),
          { html: `${x.pass} / ${x.experiments}`, cls: 'n' },
          { html: x.fail.length ? String(x.fail.length) : '0', cls: 'n' + (x.fail.length ? ' bad' : '') },
          { html: esc([x.error.length ? `${x.error.length} error` : '', x.refused.length ? `${x.refused.length} refused` : '',
            x.not_built.length ? `${x.not_built.length} not built` : '',
            x.not_applicable.length ? `${x.not_applicable.length} n/a` : ''].filter(Boolean).join(', ') || '—'),
          title: x.not_applicable.length ? `not applicable (model predictions): ${x.not_applicable.join(', ')}` : '' },
          { html: x.worst ? `${num(x.worst.error_over_tolerance)}× <span class="muted">(${esc(x.worst.experiment)})</span>` : '—', cls: 'n' },
          { html: num(x.total_wall_seconds), cls: 'n' },
          { html: num(x.median_wall_seconds_per_experiment), cls: 'n' },
        ]), 'verdict-table');
    }
    return {
      html,
      data: { sentences: sentences.map((s) => s.replace(/<[^>]+>/g, '')), engine_variants: v },
      csv: v ? [{ name: 'verdict', header: ['engine', 'variant', 'experiments', 'pass', 'fail', 'error', 'refused', 'not_built', 'not_applicable',
        'worst_experiment', 'worst_error_over_tolerance', 'total_wall_seconds', 'median_wall_seconds_per_experiment'],
      rows: v.map((x) => [...x.ev.split(' '), x.experiments, x.pass, x.fail.length, x.error.length, x.refused.length, x.not_built.length,
        x.not_applicable.length, x.worst ? x.worst.experiment : '', x.worst ? x.worst.error_over_tolerance : null, x.total_wall_seconds, x.median_wall_seconds_per_experiment]) }] : [],
    };
  },
};
