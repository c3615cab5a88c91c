// Comparison metrics of `polydyn compare` (metrics.csv): one table per scene.
import { esc, num, table } from '../lib/html.mjs';
import { METRICS_HEADER } from '../lib/inputs.mjs';

const LABELS = {
  pos_err_final: 'position error, final (/size)', pos_err_rms: 'position error, RMS (/size)', rot_err_final_rad: 'rotation error, final (rad)',
  rot_err_rms_rad: 'rotation error, RMS (rad)', energy_drift_rel: 'energy drift (rel.)', momentum_drift_rel: 'momentum drift (rel.)',
  max_penetration_over_size: 'max penetration (/size)', wall_per_sim_second: 'wall s per sim. s', steps: 'steps',
};

// "BODY:e;BODY:e;…" in a few words (the whole on hover): the count and the range of e. impacts.csv and the
// section above list every impact.
function bounces(text) {
  if (!text) return { html: '—', cls: 'n' };
  const es = text.split(';').map((x) => Number(x.slice(x.lastIndexOf(':') + 1))).filter(Number.isFinite);
  if (!es.length) return { html: esc(text), cls: 'v' };
  const lo = Math.min(...es), hi = Math.max(...es);
  return { html: `${es.length} bounce${es.length === 1 ? '' : 's'}, e ${num(lo)}${hi > lo ? `–${num(hi)}` : ''}`, cls: 'nowrap', title: text };
}

export default {
  id: 'compare',
  title: 'Comparison metrics',
  inputs: ['metrics.csv'],
  build(ctx) {
    const m = ctx.metrics;
    if (!m || !m.rows.length) return null;
    const cols = METRICS_HEADER.slice(4, 13);
    let html = '<p>From <code>polydyn compare</code>: each engine against the reference named in the table.</p>';
    const scenes = [...new Set(m.rows.map((r) => r.scene))];
    for (const scene of scenes) {
      const rows = m.rows.filter((r) => r.scene === scene);
      html += `<h3>${esc(scene)}</h3>`;
      html += table(['engine variant', 'reference', ...cols.map((c) => esc(LABELS[c])), 'bounces (restitution)'],
        rows.map((r) => [esc(r.ev), { html: esc(r.reference), cls: 'nowrap' }, ...cols.map((c) => ({ html: c === 'steps' && r[c] !== null ? String(r[c]) : num(r[c]), cls: 'n', title: String(r[c] ?? '') })),
          bounces(r.restitution_impacts)]), 'metrics');
    }
    return { html, data: m.rows, csv: [] };
  },
};
