// HTML helpers: escaping, number formatting for reading, engine colours, small table builder.

export function esc(s) {
  return String(s ?? '').replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' })[c]);
}

// A number for reading: 3 significant digits, scientific outside [1e-3, 1e5); "—" for none.
export function num(x, digits = 3) {
  if (x === null || x === undefined) return '—';
  if (Number.isNaN(x)) return 'nan';
  if (!Number.isFinite(x)) return x > 0 ? '∞' : '−∞';
  if (x === 0) return '0';
  const a = Math.abs(x);
  if (a >= 1e-3 && a < 1e5) {
    const s = x.toPrecision(digits);
    return s.includes('e') ? String(Number(s)) : s.includes('.') ? s.replace(/\.?0+$/, '') || '0' : s;
  }
  const [m, e] = x.toExponential(digits - 1).split('e');
  return `${m.replace(/\.?0+$/, '')}e${Number(e)}`;
}

// An error or tolerance: relative ones as a percentage.
export function errText(x, relative) {
  if (x === null || x === undefined) return '—';
  return relative && Number.isFinite(x) ? `${num(100 * x)} %` : num(x);
}

// The exact value, for a title attribute (hover shows it).
export function exact(x) {
  return x === null || x === undefined ? '' : String(x);
}

// Fixed colours per engine-variant, the same in every chart of the report.
const KNOWN = {
  'soft implicit': '#1f5fbf', 'soft adaptive': '#7b3fbf', 'soft fixed': '#6a9de0', 'soft embedded': '#0b2f6b',
  'ode native': '#c0392b', 'ode matched': '#e8877c',
  'bullet native': '#1e8449', 'bullet matched': '#7dcea0',
};
const OTHERS = ['#8e44ad', '#d68910', '#17a2b8', '#7f8c8d', '#b03a7a', '#5d6d7e'];
export const ANALYTIC_COLOR = '#222222';

export function colorOf(ev, all) {
  if (KNOWN[ev]) return KNOWN[ev];
  const others = all.filter((x) => !KNOWN[x]);
  return OTHERS[Math.max(0, others.indexOf(ev)) % OTHERS.length];
}

// <table> from a header (array of HTML strings) and rows (arrays of HTML strings or {html, cls, title}).
export function table(header, rows, cls = '') {
  const cell = (tag, c) => {
    if (c && typeof c === 'object') {
      const attrs = [c.cls ? ` class="${esc(c.cls)}"` : '', c.title ? ` title="${esc(c.title)}"` : '', c.attrs || ''].join('');
      return `<${tag}${attrs}>${c.html}</${tag}>`;
    }
    return `<${tag}>${c ?? ''}</${tag}>`;
  };
  return `<table${cls ? ` class="${cls}"` : ''}><thead><tr>${header.map((h) => cell('th', h)).join('')}</tr></thead>` +
    `<tbody>${rows.map((r) => `<tr>${r.map((c) => cell('td', c)).join('')}</tr>`).join('\n')}</tbody></table>`;
}

// A list of names, cut after `max` with a count of the rest (the full list in the title).
export function shortList(names, max = 6) {
  if (names.length <= max) return esc(names.join(', '));
  return `<span title="${esc(names.join(', '))}">${esc(names.slice(0, max).join(', '))} and ${names.length - max} more</span>`;
}
