// The words of a compared scene's first screen: one sentence per engine saying where (the body), when (the
// first divergence) and why (model or chaos; the impacts' restitution) it differs from the reference, from
// divergence.csv, impacts.csv and metrics.csv (docs/compare-report.md).
import { esc, num } from './html.mjs';

const REFERENCE = 'soft reference', CHAOS = 'soft chaos';

export const VERDICT_WORDS = {
  agrees: 'agrees within the threshold', chaos: 'within what chaos explains', model: 'a difference of model',
  own_divergence: 'the scene’s own divergence', unknown: 'no chaos run to tell',
};

// the median: a pile's many glancing impacts give a few wild restitutions
const median = (xs) => {
  if (!xs.length) return null;
  const s = [...xs].sort((a, b) => a - b), k = s.length >> 1;
  return s.length % 2 ? s[k] : 0.5 * (s[k - 1] + s[k]);
};

// The bodies by their largest error over time and engines (chaos run excluded), worst first.
export function bodyOrder(d, engines) {
  const worst = new Map();
  for (const r of d.series) {
    if (!worst.has(r.body)) worst.set(r.body, 0);
    if (!engines.includes(r.ev)) continue;
    const e = Math.max(r.pos_err ?? 0, r.rot_err_rad ?? 0);
    if (e > worst.get(r.body)) worst.set(r.body, e);
  }
  return [...worst].map(([body, w]) => ({ body, worst: w })).sort((a, b) => b.worst - a.worst || (a.body < b.body ? -1 : 1));
}

// What the impacts of `ev` say against the reference's: matched count, median restitution of both over the
// matched bounces, requested e.
function impactClause(d, ev) {
  const ref = d.impacts.filter((r) => r.ev === REFERENCE);
  if (!ref.length) return null;
  const mine = d.impacts.filter((r) => r.ev === ev);
  const matched = mine.filter((r) => r.reference_impact !== null);
  // bounces: the impacts whose restitution in the reference lies in [0, 1] (a domino pushing the next one
  // along, or a pile's impacts that overlap, give numbers outside it that are no restitution)
  const bounce = (x) => x.restitution !== null && x.restitution >= 0 && x.restitution <= 1;
  const pairs = matched.map((r) => [r, ref.find((x) => x.impact === r.reference_impact)])
    .filter(([a, b]) => b && a.restitution !== null && bounce(b));
  const e = median(pairs.map(([a]) => a.restitution)), eRef = median(pairs.map(([, b]) => b.restitution));
  const req = median(pairs.map(([, b]) => b.restitution_requested).filter((x) => x !== null));
  let text = `${matched.length} of the reference’s ${ref.length} impacts found again`;
  if (mine.length > matched.length) text += ` (${mine.length - matched.length} more of its own)`;
  if (e !== null) text += `; on the ${pairs.length} bounce${pairs.length === 1 ? '' : 's'} of both, median restitution ${num(e)} where the reference has ${num(eRef)}${req !== null ? ` (requested ${num(req)})` : ''}`;
  return text;
}

// Whether `ev`'s sliding contacts leave Coulomb's cone |F_t| <= μ F_n (one μ in the scene): the 90th percentile
// of their ratio, when it exceeds μ by more than 5 %; contacts under 1 % of the largest normal force (a corner
// brushing by) left out. A ratio below μ while sliding is not told: ODE's and Bullet's mode is read from the
// contact point's speed, which a pivoting edge's reported point has too.
function frictionClause(d, ev, mus) {
  if (mus.length !== 1) return null;
  const mu = mus[0];
  const mine = d.friction.filter((r) => r.ev === ev && r.mode === 'slip');
  if (!mine.length) return null;
  const big = Math.max(...mine.map((r) => r.fn));
  const ratios = mine.filter((r) => r.fn > 0.01 * big).map((r) => r.ft / r.fn).sort((a, b) => a - b);
  if (ratios.length < 5) return null;
  const hi = ratios[Math.ceil(0.9 * (ratios.length - 1))];
  if (hi <= 1.05 * mu) return null;
  return `its sliding contacts leave the friction cone: |F_t|/F_n up to ${num(hi)} (90th percentile) where μ is ${num(mu)}`;
}

export function summarize(d, metricsRows, mus = []) {
  const threshold = d.divergence.length ? d.divergence[0].threshold : null;
  const chaosFactor = d.divergence.length ? d.divergence[0].chaos_factor : null;
  const chaos = d.divergence.find((r) => r.ev === CHAOS) || null;
  const engines = d.divergence.map((r) => r.ev).filter((ev) => ev !== CHAOS);
  const scene = d.divergence.length ? d.divergence[0].scene : '';
  const tend = d.series.length ? Math.max(...d.series.map((r) => r.t)) : null;
  const bodyCount = new Set(d.series.map((r) => r.body)).size;
  const sentences = [];
  const horizon = chaos ? chaos.first_t : null;
  if (chaos) {
    const text = horizon === null
      ? `The scene’s own divergence (the reference repeated at twice its tolerance) stays below ${num(threshold)} over its ${num(tend)} s: it is predictable, so every difference below is the engines’.`
      : `The scene’s own divergence (the reference repeated at twice its tolerance) passes ${num(threshold)} at ${num(horizon, 4)} s (${chaos.first_body}): after that, two equally good runs differ as much.`;
    sentences.push({ text, html: `<b>Chaos:</b> ${esc(text)}` });
  }
  for (const r of d.divergence.filter((x) => x.ev !== CHAOS)) {
    const m = metricsRows.find((x) => x.ev === r.ev && x.scene === r.scene);
    let what;
    if (r.first_t === null)
      what = `stays within ${num(threshold)} of the reference throughout${m && m.pos_err_final !== null ? ` (final position error ${num(m.pos_err_final)} of a size)` : ''}`;
    else {
      what = `leaves the reference at ${num(r.first_t, 4)} s on ${r.first_body} (${r.first_kind} error ${num(r.first_error)})`;
      if (r.verdict === 'model')
        what += horizon === null || r.beyond_chaos_from < horizon
          ? `, ${horizon === null ? 'while the scene’s own divergence never reaches ' + num(threshold) : `before the scene’s own divergence does (${num(horizon, 4)} s)`}: a difference of model`
          : `; from ${num(r.beyond_chaos_from, 4)} s it is more than ${chaosFactor}× the scene’s own divergence: a difference of model`;
      else if (r.verdict === 'chaos')
        what += `, after the scene’s own divergence (${num(horizon, 4)} s) and never ${chaosFactor}× beyond it: chaos explains it`;
      else what += ' (no chaos run to tell model from chaos)';
    }
    const imp = impactClause(d, r.ev), fric = frictionClause(d, r.ev, mus);
    const text = `${r.ev} ${what}${imp ? `; ${imp}` : ''}${fric ? `; ${fric}` : ''}.`;
    sentences.push({ text, html: `<b>${esc(r.ev)}</b> ${esc(text.slice(r.ev.length + 1))}` });
  }
  return { scene, threshold, chaosFactor, engines, sentences, bodyCount, verdictWords: VERDICT_WORDS };
}
