// Many compared scenes (polydyn compare SCENE_DIR --out DIR): a row per scene — worst error, first
// divergence, the chaos verdict of each engine, cost — linking to the scene's own page (DIR/NAME/report.html,
// which polydyn report DIR writes too).
import { esc, num, table } from '../lib/html.mjs';

const CHAOS = 'soft chaos';

export default {
  id: 'scenes',
  title: 'Scenes compared',
  inputs: ['NAME/divergence.csv', 'NAME/metrics.csv'],
  build(ctx) {
    const list = ctx.compareScenes || [];
    if (!list.length) return null;
    const data = [];
    const rows = list.map(({ name, detail, metrics }) => {
      const engines = (metrics ? metrics.rows : []).filter((r) => r.reference !== 'self');
      const worst = engines.reduce((w, r) => (r.pos_err_final !== null && (!w || r.pos_err_final > w.pos_err_final) ? r : w), null);
      const div = detail.divergence.filter((r) => r.ev !== CHAOS && r.first_t !== null);
      const first = div.reduce((f, r) => (!f || r.first_t < f.first_t ? r : f), null);
      const chaos = detail.divergence.find((r) => r.ev === CHAOS);
      const verdicts = ['model', 'chaos', 'agrees'].map((v) => [v, detail.divergence.filter((r) => r.verdict === v).map((r) => r.ev)])
        .filter(([, evs]) => evs.length);
      const cost = engines.filter((r) => r.wall_per_sim_second !== null).map((r) => `${r.ev} ${num(r.wall_per_sim_second)}`);
      data.push({ scene: name, worst_engine: worst ? worst.ev : null, worst_pos_err_final: worst ? worst.pos_err_final : null,
        first_divergence_t: first ? first.first_t : null, first_divergence_engine: first ? first.ev : null, first_body: first ? first.first_body : null,
        chaos_horizon: chaos ? chaos.first_t : null, verdicts: Object.fromEntries(verdicts) });
      return [`<a href="${esc(encodeURIComponent(name))}/report.html">${esc(name)}</a>`,
        { html: worst ? `${num(worst.pos_err_final)} <span class="muted">${esc(worst.ev)}</span>` : '—', cls: 'n' },
        { html: first ? `${num(first.first_t, 4)} s <span class="muted">${esc(first.ev)}, ${esc(first.first_body)}</span>` : 'never', cls: 'n' },
        { html: chaos && chaos.first_t !== null ? `${num(chaos.first_t, 4)} s` : 'never', cls: 'n' },
        verdicts.map(([v, evs]) => `<b>${v}</b>: ${esc(evs.join(', '))}`).join('<br>'),
        { html: cost.map(esc).join('<br>'), cls: 'n' }];
    });
    const html = '<p>One row per scene of the directory; each name opens that scene’s page (where, when and why its engines differ). ' +
      'Worst error: the largest final position error over the engines (of a body’s size); first divergence: the earliest time any engine ' +
      'passes the threshold, and where; horizon: when the scene’s own divergence (the chaos run) passes it; verdict per engine; cost: wall ' +
      'seconds per simulated second.</p>' +
      table(['scene', 'worst final error', 'first divergence', 'scene’s own horizon', 'verdict', 'cost (wall s / sim s)'], rows, 'scenes');
    return { html, data, csv: [] };
  },
};
