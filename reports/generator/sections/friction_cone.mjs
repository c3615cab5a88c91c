// Friction cone: stopping distance against push direction, polar. An isotropic cone gives a circle.
import { esc, num, table, ANALYTIC_COLOR } from '../lib/html.mjs';

export default {
  id: 'friction-cone',
  title: 'Friction cone',
  inputs: ['results.csv'],
  build(ctx) {
    const cones = ctx.frictionCone;
    if (!cones) return null;
    let html = '<p>A block pushed along different directions relative to its edges must slide the same distance ' +
      '(Coulomb friction is isotropic): each engine’s trace should lie on the expected circle. ' +
      'A pyramid (box) friction approximation is up to √2 stronger along the diagonals of its box, so the block stops short there. Spread = (max − min) / mean over the directions.</p>';
    for (const cone of cones) {
      const angles = [...new Set(cone.traces.flatMap((t) => t.points.map((p) => p.push_deg)).concat(cone.expected.map((p) => p.push_deg)))].sort((a, b) => a - b);
      const quarter = angles.every((a) => a >= 0 && a <= 90);
      const series = cone.traces.map((t) => ({
        name: t.ev, type: 'line', coordinateSystem: 'polar', symbolSize: 8, lineStyle: { color: ctx.color(t.ev), width: 2 },
        itemStyle: { color: ctx.color(t.ev) }, data: t.points.map((p) => [p.distance, p.push_deg]),
      }));
      if (cone.expected.length) {
        series.push({ name: 'expected', type: 'line', coordinateSystem: 'polar', symbol: 'none',
          lineStyle: { color: ANALYTIC_COLOR, type: 'dashed', width: 1.5 }, itemStyle: { color: ANALYTIC_COLOR },
          data: densify(cone.expected) });
      }
      html += `<h3>${esc(cone.experiment)}</h3><div class="row">`;
      html += ctx.chart({
        tooltip: { trigger: 'item', formatter: 'polar' },
        legend: { top: 0 },
        polar: { center: quarter ? ['10%', '90%'] : ['50%', '55%'], radius: quarter ? '150%' : '70%' },
        angleAxis: quarter
          ? { type: 'value', min: 0, max: 90, startAngle: 0, endAngle: 90, clockwise: false, interval: 15, axisLabel: { formatter: 'deg' } }
          : { type: 'value', min: 0, max: 360, startAngle: 0, clockwise: false, interval: 30, axisLabel: { formatter: 'deg' } },
        radiusAxis: { type: 'value', min: 0, name: `stopping distance${cone.unit ? ' (' + cone.unit + ')' : ''}`, nameLocation: 'middle', nameGap: 22 },
        series,
      }, { height: 420, width: 520 });
      const evs = cone.traces.map((t) => t.ev);
      const rows = angles.map((a) => [
        { html: `${num(a)}°`, cls: 'n' },
        { html: num(cone.expected.find((p) => p.push_deg === a)?.distance ?? null, 4), cls: 'n' },
        ...cone.traces.map((t) => {
          const p = t.points.find((q) => q.push_deg === a);
          return p ? { html: num(p.distance, 4), cls: `n st-${p.status}`, title: String(p.distance) } : { html: '—', cls: 'n muted' };
        }),
      ]);
      rows.push([{ html: 'spread', cls: 'n' }, { html: '', cls: 'n' },
        ...cone.traces.map((t) => ({ html: t.spread === null ? '—' : `${num(100 * t.spread, 2)} %`, cls: 'n' }))]);
      html += table(['push', 'expected', ...evs.map(esc)], rows, 'cone') + '</div>';
    }
    return {
      html,
      data: cones,
      csv: [{ name: 'friction-cone', header: ['experiment', 'engine', 'variant', 'push_deg', 'distance', 'expected', 'status'],
        rows: cones.flatMap((c) => c.traces.flatMap((t) => t.points.map((p) => [c.experiment, ...t.ev.split(' '), p.push_deg, p.distance,
          c.expected.find((q) => q.push_deg === p.push_deg)?.distance ?? null, p.status]))) }],
    };
  },
};

// The expected distance as a smooth curve: points every degree between the given directions
// (linear in distance, so a constant distance draws a circular arc).
function densify(expected) {
  const pts = [...expected].sort((a, b) => a.push_deg - b.push_deg);
  const out = [];
  for (let k = 0; k < pts.length; ++k) {
    out.push([pts[k].distance, pts[k].push_deg]);
    if (k + 1 < pts.length) {
      const a = pts[k], b = pts[k + 1];
      for (let d = Math.ceil(a.push_deg + 1e-9); d < b.push_deg; ++d)
        out.push([a.distance + (b.distance - a.distance) * (d - a.push_deg) / (b.push_deg - a.push_deg), d]);
    }
  }
  return out;
}
