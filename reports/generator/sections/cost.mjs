// Cost table: wall time of the Gedanken runs and, per swept scene, the cost to reach the target error.
import { esc, num, table } from '../lib/html.mjs';

export default {
  id: 'cost',
  title: 'Cost',
  inputs: ['results.csv', 'sweep.csv'],
  build(ctx) {
    const c = ctx.cost;
    if (!c) return null;
    const hasRuns = c.rows.some((r) => r.experiments > 0);
    const header = ['engine variant'];
    if (hasRuns) header.push('experiments run', 'wall time, total (s)', 'wall time, median per experiment (s)');
    for (const s of c.scenes)
      header.push(`${esc(s)}: s per simulated s to ${c.self_convergence[s] ? 'self-convergence error' : 'error'} ${num(c.target)}`);
    const rows = c.rows.map((r) => {
      const row = [esc(r.ev)];
      if (hasRuns) row.push({ html: String(r.experiments), cls: 'n' }, { html: num(r.total_wall_seconds), cls: 'n' },
        { html: num(r.median_wall_seconds_per_experiment), cls: 'n' });
      for (const s of c.scenes) {
        const t = r.to_target[s];
        if (!t) row.push({ html: '—', cls: 'n muted', title: 'not swept' });
        else if (t.kind === 'never') row.push({ html: 'never', cls: 'n bad', title: 'no setting swept reaches the target error' +
          (c.self_convergence[s] ? ' against its own finest run (a chaotic scene: see the horizon of predictability)' : '') });
        else row.push({ html: (t.kind === 'at_most' ? '≤ ' : '') + num(t.wall_per_sim_second), cls: 'n',
          title: t.kind === 'at_most' ? `already reached at the loosest setting (${t.setting_value}) of ${t.curve}` : `interpolated on ${t.curve}` });
      }
      return row;
    });
    let html = table(header, rows, 'cost');
    const anySelf = c.scenes.some((s) => c.self_convergence[s]);
    html += `<p class="legend">Wall times are those the runs measured on the machine that ran them. The cost to reach error ${num(c.target)} is read on ` +
      (anySelf ? 'the self-convergence curve (each engine against its own finest run; the error against the reference where a sweep has no ' +
        'self-convergence column), ' : 'the work-precision curve, ') +
      'read where the curve reaches it and stays (one setting within it between two outside is luck), interpolated linearly in log error–log cost between the settings on either side; "≤" when the loosest ' +
      'setting swept is already accurate enough; "never" when no setting swept gets there; the cheapest curve of an engine-variant counts.</p>';
    return {
      html,
      data: c,
      csv: [{ name: 'cost', header: ['engine', 'variant', 'experiments', 'total_wall_seconds', 'median_wall_seconds_per_experiment', 'scene',
        'target_error', 'to_target', 'wall_per_sim_second'],
      rows: c.rows.flatMap((r) => (c.scenes.length ? c.scenes : ['']).map((s) => {
        const t = s ? r.to_target[s] : null;
        return [...r.ev.split(' '), r.experiments, r.total_wall_seconds, r.median_wall_seconds_per_experiment, s, s ? c.target : null,
          t ? t.kind : '', t ? t.wall_per_sim_second : null];
      })) }],
    };
  },
};
