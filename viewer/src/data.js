// Run data of a replay element: the JSON block written by polydyn view and one base64 block per run
// (layout in viewer/c/view_internal.h: float64 times and poses, float32 velocities and contacts).

function decodeBase64(text) {
  if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(text.trim());
  const binary = atob(text.trim());
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

// One run: the summary's bodies and the sampled trajectory as typed arrays.
export class Run {
  constructor(meta, bytes) {
    Object.assign(this, meta);  // engine, scene, dir, gravity, completed, bodies, samples, moving, contacts
    const buffer = bytes.buffer;
    const at = (name, Type) => {
      const [offset, length] = meta.layout[name];
      return new Type(buffer, bytes.byteOffset + offset, length / Type.BYTES_PER_ELEMENT);
    };
    this.t = at('t', Float64Array);
    this.pose = at('pose', Float64Array);          // per sample, per moving body: x y z qw qx qy qz
    this.vel = at('vel', Float32Array);            // per sample, per moving body: vx vy vz wx wy wz
    this.contactStart = at('contactStart', Uint32Array);
    this.contactFloat = at('contactFloat', Float32Array);  // px py pz Fx Fy Fz (force on body_a)
    this.contactInt = at('contactInt', Int32Array);        // body_a body_b flags (1 EE, 2 slip)
    this.slot = new Int32Array(this.bodies.length).fill(-1);  // body index → trajectory column
    this.moving.forEach((b, k) => { this.slot[b] = k; });
    this.label = this.engine;
  }

  get t0() { return this.t[0]; }
  get t1() { return this.t[this.t.length - 1]; }

  // Sample k and the fraction a ∈ [0, 1) of the way to k + 1 at time t (clamped to the run's range).
  locate(t) {
    const ts = this.t, n = ts.length;
    if (!(t > ts[0])) return [0, 0];
    if (t >= ts[n - 1]) return [n - 1, 0];
    let lo = 0, hi = n - 1;  // ts[lo] <= t < ts[hi]
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (ts[mid] <= t) lo = mid; else hi = mid;
    }
    return [lo, (t - ts[lo]) / (ts[hi] - ts[lo])];
  }

  // Largest contact force magnitude met in 95 % of the contacts (arrow scale), N.
  forceScale() {
    const n = this.contacts;
    if (!n) return 0;
    const step = Math.max(1, Math.floor(n / 20000));
    const mags = [];
    for (let i = 0; i < n; i += step) {
      const f = this.contactFloat;
      mags.push(Math.hypot(f[6 * i + 3], f[6 * i + 4], f[6 * i + 5]));
    }
    mags.sort((a, b) => a - b);
    return mags[Math.min(mags.length - 1, Math.floor(0.95 * mags.length))] || mags[mags.length - 1];
  }
}

// Reads the runs of replay element `id` (section#pd-replay-ID).
export function readReplay(id) {
  const metaEl = document.getElementById(`pd-replay-${id}-meta`);
  if (!metaEl) throw new Error(`replay ${id}: no data block`);
  const meta = JSON.parse(metaEl.textContent);
  const runs = meta.runs.map((m, i) => {
    const el = document.getElementById(`pd-replay-${id}-run-${i}`);
    const bytes = decodeBase64(el.textContent);
    if (bytes.byteLength !== m.bytes) throw new Error(`replay ${id}, run ${i}: ${bytes.byteLength} bytes, expected ${m.bytes}`);
    return new Run(m, bytes);
  });
  // runs of one engine are told apart by their directories
  const engines = runs.map((r) => r.engine);
  if (new Set(engines).size < engines.length)
    runs.forEach((r) => { r.label = `${r.engine} (${r.dir.replace(/\/+$/, '').replace(/^.*\//, '')})`; });
  return { title: meta.title, runs };
}
