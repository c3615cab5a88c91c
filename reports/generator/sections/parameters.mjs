// The parameters every engine-variant actually used, read from each run's summary.json and
// deduplicated: one table per engine-variant.
import { esc, num, table, shortList } from '../lib/html.mjs';
import { parameters } from '../lib/derive.mjs';

export default {
  id: 'parameters',
  title: 'Parameters used',
  inputs: ['runs/*/*/summary.json'],
  build(ctx) {
    const runs = ctx.runs;
    if (!runs || !runs.length) return null;
    const params = parameters(runs).sort((a, b) => ctx.evOrder.indexOf(a.ev) - ctx.evOrder.indexOf(b.ev));
    let html = '<p>As the runs wrote them (<code>engine_settings</code> of the reference engines; settings, materials as used, ' +
      'the contact constants of each pair of materials and adjustments of polydyn). A value used by only some runs lists them. ' +
      'Springs and dampers belong to a pair of bodies (docs/contact-model.md): a material’s k and c are shown only where the ' +
      'scene set them (— otherwise); a modal damper’s c is the one of a single contact at the pair’s reduced mass.</p>';
    const csv = [];
    for (const p of params) {
      const all = p.runs.length;
      html += `<div class="param-block${p.materials.length ? ' wide' : ''}"><h3>${esc(p.ev)} <span class="muted">(${all} run${all === 1 ? '' : 's'})</span></h3>`;
      if (p.missing.length) html += `<p class="bad">No summary.json: ${shortList(p.missing)}.</p>`;
      const srows = [];
      for (const s of p.settings) {
        for (const v of s.values) {
          srows.push([`<code>${esc(s.key)}</code>`, { html: esc(v.value), cls: 'v' }, v.used_by.length === all ? `all` : shortList(v.used_by)]);
          csv.push([...p.ev.split(' '), 'setting', s.key, v.value, v.used_by.join(' ')]);
        }
      }
      if (srows.length) html += table(['setting', 'value', 'used by'], srows, 'params');
      if (p.materials.length) {
        html += table(['μ', 'k_n (N/m)', 'k_t (N/m)', 'c_n (N·s/m)', 'c_t (N·s/m)', 'e', 'ζ', 'requested', 'bodies'],
          p.materials.map((m) => [...['mu', 'kn', 'kt', 'cn', 'ct', 'restitution', 'zeta'].map((k) => ({ html: num(m.used[k], 4), cls: 'n', title: String(m.used[k] ?? '') })),
            esc(Object.entries(m.requested).map(([k, v]) => `${k} ${v}`).join(', ') || '—'), shortList(m.bodies, 4)]), 'params');
        for (const m of p.materials) csv.push([...p.ev.split(' '), 'material', JSON.stringify(m.requested), JSON.stringify(m.used), m.bodies.join(' ')]);
      }
      if (p.pairs.length) {
        const keys = ['mu', 'restitution', 'zeta_n', 'zeta_t', 'kn', 'kt', 'cn', 'ct', 'm_pair', 'period', 'delta_max'];
        html += table(['pair μ', 'e', 'ζ_n', 'ζ_t', 'k_n (N/m)', 'k_t (N/m)', 'c_n (N·s/m)', 'c_t (N·s/m)', 'm_pair (kg)', 'period (s)', 'δ_max (m)',
          'dampers', 'bodies'],
          p.pairs.map((c) => [...keys.map((k) => ({ html: num(c.used[k], 4), cls: 'n', title: String(c.used[k] ?? '') })),
            esc(c.used.damping ? `n ${c.used.damping.n}, t ${c.used.damping.t}` : '—'), shortList(c.bodies, 4)]), 'params');
        for (const c of p.pairs) csv.push([...p.ev.split(' '), 'pair', c.bodies.join(' '), JSON.stringify(c.used), '']);
      }
      if (p.adjustments.length) {
        html += '<p>Adjustments (§3.3):</p><ul class="adjust">' +
          p.adjustments.map((a) => `<li>${esc(a.text)} <span class="muted">— ${a.used_by.length === all ? 'all runs' : shortList(a.used_by)}</span></li>`).join('') + '</ul>';
        for (const a of p.adjustments) csv.push([...p.ev.split(' '), 'adjustment', a.text, '', a.used_by.join(' ')]);
      } else if (p.materials.length) html += '<p class="muted">Adjustments: none.</p>';
      html += '</div>';
    }
    html = html.replace(/(<div class="param-block)/, '<div class="param-grid">$1') + '</div>';
    return { html, data: params, csv: [{ name: 'parameters', header: ['engine', 'variant', 'kind', 'key', 'value', 'used_by'], rows: csv }] };
  },
};
