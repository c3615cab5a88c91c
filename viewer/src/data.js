// Run data of a replay: either a replay element's JSON block written by polydyn view and one base64
// block per run (layout in viewer/c/view_internal.h: float64 times and poses, float32 velocities and
// contacts), or a run directory's files as the report hands them over (readRunFiles: the same arrays,
// read from summary.json, trajectory.csv and contacts.csv as viewer/c/view_run.c reads them).
import { parseCsvRecords } from './csv.js';

function decodeBase64(text) {
  if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(text.trim());
  const binary = atob(text.trim());
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

// The typed arrays of a data block (meta.layout: [offset, bytes] of each).
function blockArrays(meta, bytes) {
  const at = (name, Type) => {
    const [offset, length] = meta.layout[name];
    return new Type(bytes.buffer, bytes.byteOffset + offset, length / Type.BYTES_PER_ELEMENT);
  };
  return {
    t: at('t', Float64Array), pose: at('pose', Float64Array), vel: at('vel', Float32Array),
    contactStart: at('contactStart', Uint32Array), contactFloat: at('contactFloat', Float32Array),
    contactInt: at('contactInt', Int32Array),
  };
}

// One run: the summary's bodies and the sampled trajectory as typed arrays.
export class Run {
  constructor(meta, arrays) {
    Object.assign(this, meta);  // engine, scene, dir, gravity, completed, bodies, samples, moving, contacts
    this.t = arrays.t;                        // per sample
    this.pose = arrays.pose;                  // per sample, per moving body: x y z qw qx qy qz
    this.vel = arrays.vel;                    // per sample, per moving body: vx vy vz wx wy wz
    this.contactStart = arrays.contactStart;  // per sample + 1: contacts of sample s are [start[s], start[s+1])
    this.contactFloat = arrays.contactFloat;  // px py pz Fx Fy Fz (force on body_a)
    this.contactInt = arrays.contactInt;      // body_a body_b flags (1 EE, 2 slip)
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
    return new Run(m, blockArrays(m, bytes));
  });
  // runs of one engine are told apart by their directories
  labelDuplicates(runs);
  return { title: meta.title, runs };
}

// Runs of the same engine are told apart by their directory's last component.
function labelDuplicates(runs) {
  const engines = runs.map((r) => r.engine);
  if (new Set(engines).size < engines.length)
    runs.forEach((r) => { r.label = `${r.engine} (${r.dir.replace(/\/+$/, '').replace(/^.*\//, '')})`; });
}

// ---------------------------------------------------------------- a run directory's files
// A port of viewer/c/view_run.c (read_summary, read_trajectory, read_contacts) for the report's
// PolydynViewer.mount: the same checks and the same arrays, so Replay cannot tell the two apart.

const TRAJECTORY_HEADER = 't,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz';
const CONTACTS_HEADER = 't,body_a,body_b,kind,feat_a,feat_b,px,py,pz,nx,ny,nz,fn,ftx,fty,ftz,mode';
const EDGE_EDGE = 1, SLIP = 2;

const isNumber = (x) => typeof x === 'number' && Number.isFinite(x);
const numbers = (a, n) => Array.isArray(a) && a.length === n && a.every(isNumber) ? a : null;

// summary.json writes q as [w, [x, y, z]]; [w, x, y, z] is accepted too
function quaternion(q) {
  if (numbers(q, 4)) return q;
  if (Array.isArray(q) && q.length === 2 && isNumber(q[0]) && numbers(q[1], 3)) return [q[0], ...q[1]];
  return null;
}

function readBody(b, index, where) {
  const inertia = Array.isArray(b?.inertia) && b.inertia.length === 3 && b.inertia.every((r) => numbers(r, 3));
  const x = numbers(b?.initial?.x, 3), q = quaternion(b?.initial?.q);
  if (typeof b?.name !== 'string' || typeof b.color !== 'string' || typeof b.fixed !== 'boolean' || !isNumber(b.mass) ||
      !isNumber(b.size) || !inertia || !x || !q || typeof b.shape !== 'object' || !b.shape)
    throw new Error(`${where}: body ${index}: needs name, color, fixed, mass, size, inertia, initial x and q, shape`);
  const { vertices, faces } = b.shape;
  if (!Array.isArray(vertices) || vertices.length < 4 || !Array.isArray(faces) || faces.length < 4)
    throw new Error(`${where}: body '${b.name}': shape needs at least 4 vertices and 4 faces`);
  if (!vertices.every((v) => numbers(v, 3))) throw new Error(`${where}: body '${b.name}': a vertex is not 3 numbers`);
  if (!faces.every((f) => Array.isArray(f) && f.length >= 3 && f.every((i) => Number.isInteger(i) && i >= 0 && i < vertices.length)))
    throw new Error(`${where}: body '${b.name}': a face is not 3 or more vertex indices`);
  return {
    name: b.name, color: b.color, fixed: b.fixed, mass: b.mass, size: b.size, inertia: b.inertia.flat(), x, q,
    vertices: vertices.flat(), faces,
  };
}

function readSummary(summary, dir) {
  const where = `${dir}/summary.json`;
  if (!summary || typeof summary !== 'object') throw new Error(`${where}: missing`);
  const gravity = numbers(summary.settings?.gravity, 3);
  if (typeof summary.engine !== 'string' || typeof summary.scene !== 'string' || !gravity ||
      !Array.isArray(summary.bodies) || summary.bodies.length < 1)
    throw new Error(`${where}: not a polydyn run summary (needs engine, scene, settings.gravity, bodies)`);
  const bodies = summary.bodies.map((b, i) => readBody(b, i, where));
  const names = new Set();
  for (const b of bodies) {
    if (names.has(b.name)) throw new Error(`${where}: two bodies named '${b.name}'`);
    names.add(b.name);
  }
  const moving = [];
  bodies.forEach((b, i) => { if (!b.fixed) moving.push(i); });
  return {
    engine: summary.engine, scene: summary.scene, dir, gravity, completed: summary.completed !== false, bodies, moving,
  };
}

// The records of a CSV text after its header, which must equal `header`, as [line, fields] (src/csv.js).
function* csvRows(text, header, where) {
  const records = parseCsvRecords(text, (line, message) => { throw new Error(`${where}:${line}: ${message}`); });
  if (records.length === 0 || records[0].fields.join(',') !== header)
    throw new Error(`${where}:1: expected the header '${header}'`);
  for (let i = 1; i < records.length; ++i) yield [records[i].line, records[i].fields];
}

function number(field, where) {
  const v = field.trim() === field && field !== '' ? Number(field) : NaN;
  if (!Number.isFinite(v)) throw new Error(`${where}: not a finite number: '${field.slice(0, 40)}'`);
  return v;
}

// A growable typed array.
class Grow {
  constructor(Type) { this.Type = Type; this.a = new Type(1024); this.n = 0; }
  push(v) {
    if (this.n === this.a.length) { const b = new this.Type(2 * this.n); b.set(this.a); this.a = b; }
    this.a[this.n++] = v;
  }
  done() { return this.a.slice(0, this.n); }
}

function readTrajectory(text, meta) {
  const where = `${meta.dir}/trajectory.csv`, m = meta.moving.length;
  if (m === 0) throw new Error(`${where}: the scene has no moving body`);
  const t = new Grow(Float64Array), pose = new Grow(Float64Array), vel = new Grow(Float32Array);
  let row = 0, line = 1;
  for (const [n, f] of csvRows(text, TRAJECTORY_HEADER, where)) {
    line = n;
    const at = `${where}:${n}`;
    const time = number(f[0], at);
    if (row === 0) {
      if (t.n > 0 && !(time > t.a[t.n - 1])) throw new Error(`${at}: time ${time} does not increase`);
      t.push(time);
    } else if (time !== t.a[t.n - 1]) {
      throw new Error(`${at}: sample at t = ${t.a[t.n - 1]} has ${row} of its ${m} moving bodies`);
    }
    const expected = meta.bodies[meta.moving[row]].name;
    if (f[1] !== expected) throw new Error(`${at}: expected body '${expected}' (moving bodies in scene order)`);
    if (f.length < 15) throw new Error(`${at}: expected 15 fields, found ${f.length}`);
    if (f.length > 15) throw new Error(`${at}: more than 15 fields`);
    for (let c = 2; c < 9; ++c) pose.push(number(f[c], at));
    for (let c = 9; c < 15; ++c) vel.push(number(f[c], at));
    row = (row + 1) % m;
  }
  if (row !== 0) throw new Error(`${where}:${line}: the last sample has ${row} of its ${m} moving bodies`);
  if (t.n === 0) throw new Error(`${where}: no samples`);
  return { t: t.done(), pose: pose.done(), vel: vel.done() };
}

function readContacts(text, meta, ts) {
  const where = `${meta.dir}/contacts.csv`, S = ts.length;
  const start = new Uint32Array(S + 1), cf = new Grow(Float32Array), ci = new Grow(Int32Array);
  const index = new Map(meta.bodies.map((b, i) => [b.name, i]));
  let sample = 0, count = 0;
  if (text != null) {
    for (const [n, f] of csvRows(text, CONTACTS_HEADER, where)) {
      const at = `${where}:${n}`;
      if (f.length !== 17) throw new Error(`${at}: expected 17 fields, found ${f.length}`);
      const t = number(f[0], at);
      while (sample < S && ts[sample] < t) start[++sample] = count;
      if (sample === S || ts[sample] !== t) throw new Error(`${at}: time ${t} is not a trajectory sample (or goes back)`);
      const a = index.get(f[1]), b = index.get(f[2]);
      for (const [name, i] of [[f[1], a], [f[2], b]])
        if (i === undefined) throw new Error(`${at}: no body named '${name.slice(0, 60)}' in summary.json`);
      let flags = 0;
      if (f[3] === 'EE') flags |= EDGE_EDGE;
      else if (f[3] !== 'VF') throw new Error(`${at}: kind must be VF or EE`);
      const v = f.slice(4, 16).map((x) => number(x, at));  // feat_a, feat_b, p, n, fn, ft
      if (f[16] === 'slip') flags |= SLIP;
      else if (f[16] !== 'stick') throw new Error(`${at}: mode must be stick or slip`);
      // force on body_a: fn along n plus the tangential force
      for (let k = 0; k < 3; ++k) cf.push(v[2 + k]);
      for (let k = 0; k < 3; ++k) cf.push(v[8] * v[5 + k] + v[9 + k]);
      ci.push(a); ci.push(b); ci.push(flags);
      count++;
    }
  }
  while (sample < S) start[++sample] = count;
  return { contactStart: start, contactFloat: cf.done(), contactInt: ci.done(), contacts: count };
}

// PolydynViewer.mount's input: one run directory's files, or { title, runs: [files, ...] } — several
// shown together, the first drawn solid and the others as overlays — into { title, runs: [Run] }, as readReplay.
export function readRunFiles(files) {
  if (!Array.isArray(files?.runs)) return readOneRun(files);
  if (files.runs.length === 0) throw new Error('no runs to show');
  const runs = files.runs.map((f) => readOneRun(f).runs[0]);
  labelDuplicates(runs);
  return { title: String(files.title ?? runs.map((r) => r.dir).join(' + ')), runs };
}

function readOneRun({ run, summary, trajectory, contacts }) {
  const dir = String(run ?? 'run');
  if (typeof trajectory !== 'string') throw new Error(`${dir}: no trajectory.csv`);
  const meta = readSummary(summary, dir);
  const traj = readTrajectory(trajectory, meta);
  const cont = readContacts(contacts, meta, traj.t);
  Object.assign(meta, { samples: traj.t.length, contacts: cont.contacts, hasContacts: contacts != null });
  return { title: `${dir}: ${meta.engine}`, runs: [new Run(meta, { ...traj, ...cont })] };
}
