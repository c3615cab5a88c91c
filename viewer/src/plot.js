// The small plot under the 3-D view: one quantity of the selected body over time, one line per run,
// and the playhead. The lines are drawn once into an offscreen canvas (min/max per pixel column, so a
// long run costs no more than a short one); each frame only copies it and draws the playhead.

export const QUANTITIES = {
  height: { label: 'height of the centre of mass', unit: 'm' },
  speed: { label: 'speed of the centre of mass', unit: 'm/s' },
  energy: { label: 'energy (kinetic + rotational + potential)', unit: 'J' },
};

// The quantity for body b of run over all samples (Float64Array), or null for a fixed body.
export function series(run, b, quantity) {
  const k = run.slot[b];
  if (k < 0) return null;
  const m = run.moving.length, S = run.t.length, out = new Float64Array(S);
  const g = run.gravity, gn = Math.hypot(g[0], g[1], g[2]);
  const up = gn > 0 ? [-g[0] / gn, -g[1] / gn, -g[2] / gn] : [0, 0, 1];
  const body = run.bodies[b], I = body.inertia, mass = body.mass;
  for (let s = 0; s < S; ++s) {
    const i = (s * m + k) * 7, j = (s * m + k) * 6, P = run.pose, V = run.vel;
    const h = up[0] * P[i] + up[1] * P[i + 1] + up[2] * P[i + 2];
    if (quantity === 'height') { out[s] = h; continue; }
    const v2 = V[j] * V[j] + V[j + 1] * V[j + 1] + V[j + 2] * V[j + 2];
    if (quantity === 'speed') { out[s] = Math.sqrt(v2); continue; }
    // ω in the body frame: Rᵀ ω, with R from q (body → world)
    const w = P[i + 3], x = P[i + 4], y = P[i + 5], z = P[i + 6];
    const R = [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)];
    const o = [V[j + 3], V[j + 4], V[j + 5]];
    const ob = [0, 1, 2].map((c) => R[c] * o[0] + R[3 + c] * o[1] + R[6 + c] * o[2]);
    let rot = 0;
    for (let r = 0; r < 3; ++r) for (let c = 0; c < 3; ++c) rot += ob[r] * I[3 * r + c] * ob[c];
    out[s] = 0.5 * mass * v2 + 0.5 * rot + mass * gn * h;
  }
  return out;
}

function niceTicks(lo, hi, count) {
  const span = hi - lo || 1, step0 = span / count, mag = 10 ** Math.floor(Math.log10(step0));
  const step = [1, 2, 5, 10].map((f) => f * mag).find((s) => s >= step0);
  const ticks = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step) ticks.push(Math.abs(v) < 1e-12 * span ? 0 : v);
  return ticks;
}

export class Plot {
  constructor(canvas) {
    this.canvas = canvas;
    this.cache = document.createElement('canvas');
    this.lines = [];
    this.t0 = 0;
    this.t1 = 1;
    this.title = '';
  }

  // lines: [{ color, t, y }]; t0, t1: the time axis
  set(lines, t0, t1, title, unit) {
    Object.assign(this, { lines, t0, t1, title, unit });
    this.redraw();
  }

  get margin() { return { l: 56, r: 10, t: 16, b: 18 }; }

  redraw() {
    const dpr = window.devicePixelRatio || 1, w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    if (!w || !h) return;
    this.canvas.width = this.cache.width = Math.round(w * dpr);
    this.canvas.height = this.cache.height = Math.round(h * dpr);
    const ctx = this.cache.getContext('2d');
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = '#181b21';
    ctx.fillRect(0, 0, w, h);
    const M = this.margin, pw = w - M.l - M.r, ph = h - M.t - M.b;
    ctx.font = '11px system-ui, sans-serif';
    ctx.fillStyle = '#aab';
    ctx.fillText(this.title, M.l, 11);
    let lo = Infinity, hi = -Infinity;
    for (const L of this.lines) for (const v of L.y) { if (v < lo) lo = v; if (v > hi) hi = v; }
    if (!this.lines.length || !isFinite(lo)) {
      ctx.fillText('select a moving body (click it, or pick its name)', M.l, M.t + ph / 2);
      this.finish();
      return;
    }
    if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) { hi += 0.5; lo -= 0.5; }
    const pad = 0.05 * (hi - lo);
    lo -= pad; hi += pad;
    this.map = { x: (t) => M.l + ((t - this.t0) / (this.t1 - this.t0 || 1)) * pw, y: (v) => M.t + (1 - (v - lo) / (hi - lo)) * ph };
    ctx.strokeStyle = '#333a44';
    ctx.lineWidth = 1;
    ctx.fillStyle = '#889';
    ctx.textAlign = 'right';
    for (const v of niceTicks(lo, hi, 3)) {
      const y = Math.round(this.map.y(v)) + 0.5;
      ctx.beginPath(); ctx.moveTo(M.l, y); ctx.lineTo(M.l + pw, y); ctx.stroke();
      ctx.fillText(`${+v.toPrecision(4)}`, M.l - 4, y + 3);
    }
    ctx.textAlign = 'center';
    for (const t of niceTicks(this.t0, this.t1, 8)) ctx.fillText(`${+t.toPrecision(4)}`, this.map.x(t), h - 4);
    ctx.textAlign = 'left';
    for (const L of this.lines) {
      ctx.strokeStyle = L.color;
      ctx.lineWidth = 1.5;
      ctx.beginPath();
      // min/max per pixel column
      let col = -1, mn = 0, mx = 0, first = true;
      const flush = () => {
        if (col < 0) return;
        const y0 = this.map.y(mn), y1 = this.map.y(mx);
        if (first) { ctx.moveTo(col, y0); first = false; } else ctx.lineTo(col, y0);
        if (y1 !== y0) ctx.lineTo(col, y1);
      };
      for (let s = 0; s < L.t.length; ++s) {
        const x = Math.round(this.map.x(L.t[s])), v = L.y[s];
        if (x !== col) { flush(); col = x; mn = mx = v; } else { if (v < mn) mn = v; if (v > mx) mx = v; }
      }
      flush();
      ctx.stroke();
    }
    this.finish();
  }

  finish() { this.draw(this.playhead ?? this.t0); }

  // Copies the lines and draws the playhead at time t.
  draw(t) {
    this.playhead = t;
    const ctx = this.canvas.getContext('2d');
    if (!this.cache.width) return;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.drawImage(this.cache, 0, 0);
    const dpr = window.devicePixelRatio || 1, M = this.margin, h = this.canvas.height / dpr, w = this.canvas.width / dpr;
    const x = M.l + ((t - this.t0) / (this.t1 - this.t0 || 1)) * (w - M.l - M.r);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.strokeStyle = '#ffe14d';
    ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.moveTo(x, M.t); ctx.lineTo(x, h - M.b); ctx.stroke();
  }

  // Time at canvas x (CSS pixels), for seeking by clicking the plot.
  timeAt(x) {
    const M = this.margin, w = this.canvas.clientWidth;
    const f = Math.min(1, Math.max(0, (x - M.l) / (w - M.l - M.r)));
    return this.t0 + f * (this.t1 - this.t0);
  }
}
