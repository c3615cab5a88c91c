// The 3-D view: every body of a run in one merged geometry, moved by a pose texture.
//
// All polyhedra of the scene are merged into one mesh (faces, flat normals, scene colours) and one set
// of edges, each vertex tagged with its body's index. A float texture holds each body's 3×4 pose
// (rotation rows and the centre of mass); the vertex shader reads it, so a frame costs one texture
// upload and one draw call per run, whatever the number of bodies. A run is drawn with its own texture:
// the first solid, the others ghosted. Picking casts the mouse ray against the convex polyhedra on the
// CPU (clipping the ray by every face plane), in the bodies' own frames.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { sceneColor } from './colors.js';

const POSE_SHADER = /* glsl */ `
uniform sampler2D pdPose;
uniform float pdPerRow;
attribute float pdBody;
mat4 pdPoseMatrix() {
  float row = floor((pdBody + 0.5) / pdPerRow);
  int col = int(pdBody - row * pdPerRow) * 3;
  vec4 r0 = texelFetch(pdPose, ivec2(col, int(row)), 0);
  vec4 r1 = texelFetch(pdPose, ivec2(col + 1, int(row)), 0);
  vec4 r2 = texelFetch(pdPose, ivec2(col + 2, int(row)), 0);
  return mat4(r0.x, r1.x, r2.x, 0.0, r0.y, r1.y, r2.y, 0.0, r0.z, r1.z, r2.z, 0.0, r0.w, r1.w, r2.w, 1.0);
}
`;

// Makes a three.js material place each vertex by its body's pose (and turn normals when lit).
function posed(material, pose, lit) {
  material.onBeforeCompile = (shader) => {
    shader.uniforms.pdPose = pose.uniforms.pdPose;
    shader.uniforms.pdPerRow = pose.uniforms.pdPerRow;
    let v = POSE_SHADER + shader.vertexShader;
    if (lit) {
      v = v.replace('#include <beginnormal_vertex>',
        '#include <beginnormal_vertex>\nmat4 pdM = pdPoseMatrix();\nobjectNormal = mat3(pdM) * objectNormal;');
      v = v.replace('#include <begin_vertex>', '#include <begin_vertex>\ntransformed = (pdM * vec4(transformed, 1.0)).xyz;');
    } else {
      v = v.replace('#include <begin_vertex>',
        '#include <begin_vertex>\ntransformed = (pdPoseMatrix() * vec4(transformed, 1.0)).xyz;');
    }
    shader.vertexShader = v;
  };
  material.customProgramCacheKey = () => (lit ? 'pd-posed-lit' : 'pd-posed');
  return material;
}

// Rotation rows and translation of a pose, from x and a unit quaternion (w, x, y, z), into out[0..11].
export function poseRows(px, py, pz, w, x, y, z, out, o) {
  out[o] = 1 - 2 * (y * y + z * z); out[o + 1] = 2 * (x * y - w * z); out[o + 2] = 2 * (x * z + w * y); out[o + 3] = px;
  out[o + 4] = 2 * (x * y + w * z); out[o + 5] = 1 - 2 * (x * x + z * z); out[o + 6] = 2 * (y * z - w * x); out[o + 7] = py;
  out[o + 8] = 2 * (x * z - w * y); out[o + 9] = 2 * (y * z + w * x); out[o + 10] = 1 - 2 * (x * x + y * y); out[o + 11] = pz;
}

// Pose of one moving body at sample k + fraction a: position linear, rotation slerp. Writes x, q into p.
export function interpolatePose(run, slot, k, a, p) {
  const m = run.moving.length, P = run.pose;
  const i = (k * m + slot) * 7;
  if (a === 0) {
    for (let c = 0; c < 7; ++c) p[c] = P[i + c];
    return p;
  }
  const j = i + m * 7;
  for (let c = 0; c < 3; ++c) p[c] = P[i + c] + a * (P[j + c] - P[i + c]);
  let w1 = P[j + 3], x1 = P[j + 4], y1 = P[j + 5], z1 = P[j + 6];
  const w0 = P[i + 3], x0 = P[i + 4], y0 = P[i + 5], z0 = P[i + 6];
  let dot = w0 * w1 + x0 * x1 + y0 * y1 + z0 * z1;
  if (dot < 0) { dot = -dot; w1 = -w1; x1 = -x1; y1 = -y1; z1 = -z1; }
  let s0 = 1 - a, s1 = a;
  if (dot < 0.9995) {
    const th = Math.acos(dot), s = Math.sin(th);
    s0 = Math.sin((1 - a) * th) / s;
    s1 = Math.sin(a * th) / s;
  }
  const w = s0 * w0 + s1 * w1, x = s0 * x0 + s1 * x1, y = s0 * y0 + s1 * y1, z = s0 * z0 + s1 * z1;
  const n = Math.hypot(w, x, y, z);
  p[3] = w / n; p[4] = x / n; p[5] = y / n; p[6] = z / n;
  return p;
}

// Outward normal (not unit) of face f (vertex indices, counter-clockwise from outside) by Newell's
// method, robust for any planar polygon; V: flat vertex coordinates.
function faceNormal(V, f) {
  let nx = 0, ny = 0, nz = 0;
  for (let i = 0; i < f.length; ++i) {
    const p = f[i] * 3, q = f[(i + 1) % f.length] * 3;
    nx += (V[p + 1] - V[q + 1]) * (V[p + 2] + V[q + 2]);
    ny += (V[p + 2] - V[q + 2]) * (V[p] + V[q]);
    nz += (V[p] - V[q]) * (V[p + 1] + V[q + 1]);
  }
  return [nx, ny, nz];
}

// A float texture of 3×4 poses, one per body.
class PoseTexture {
  constructor(bodyCount) {
    this.perRow = Math.min(bodyCount, 1024);
    const width = 3 * this.perRow, height = Math.ceil(bodyCount / this.perRow);
    this.rows = new Float32Array(bodyCount * 12);  // what the texture holds, body by body
    this.data = new Float32Array(width * height * 4);
    this.texture = new THREE.DataTexture(this.data, width, height, THREE.RGBAFormat, THREE.FloatType);
    this.texture.magFilter = this.texture.minFilter = THREE.NearestFilter;
    this.uniforms = { pdPose: { value: this.texture }, pdPerRow: { value: this.perRow } };
  }

  // rows of body b: the texture's layout equals rows' when perRow covers every body (up to 1024 bodies)
  set(b, r, o) {
    const row = Math.floor(b / this.perRow), col = b - row * this.perRow;
    const base = (row * this.perRow * 3 + col * 3) * 4;
    for (let i = 0; i < 12; ++i) {
      this.rows[b * 12 + i] = r[o + i];
      this.data[base + i] = r[o + i];
    }
  }

  changed() { this.texture.needsUpdate = true; }
}

// Triangles (flat normals, colours) and edges of every body of `bodies`, in body frames, merged.
function buildGeometry(bodies, colors) {
  let triCount = 0, edgeCount = 0;
  for (const b of bodies) for (const f of b.faces) { triCount += f.length - 2; edgeCount += f.length; }
  const pos = new Float32Array(triCount * 9), nrm = new Float32Array(triCount * 9);
  const col = new Float32Array(triCount * 9), tag = new Float32Array(triCount * 3);
  const epos = new Float32Array(edgeCount * 3), etag = new Float32Array(edgeCount);  // half used: shared edges
  let t = 0, e = 0;
  const edgeRanges = [];
  bodies.forEach((b, bi) => {
    const V = b.vertices, c = colors[bi];
    const seen = new Set();
    const start = e;
    for (const f of b.faces) {
      const [nx, ny, nz] = faceNormal(V, f);
      const nl = Math.hypot(nx, ny, nz) || 1;
      for (let i = 1; i + 1 < f.length; ++i) {
        for (const vi of [f[0], f[i], f[i + 1]]) {
          pos.set([V[vi * 3], V[vi * 3 + 1], V[vi * 3 + 2]], t * 3);
          nrm.set([nx / nl, ny / nl, nz / nl], t * 3);
          col.set([c.r, c.g, c.b], t * 3);
          tag[t++] = bi;
        }
      }
      for (let i = 0; i < f.length; ++i) {
        const u = f[i], v = f[(i + 1) % f.length];
        const key = u < v ? u * 65536 + v : v * 65536 + u;
        if (seen.has(key)) continue;
        seen.add(key);
        epos.set([V[u * 3], V[u * 3 + 1], V[u * 3 + 2], V[v * 3], V[v * 3 + 1], V[v * 3 + 2]], e * 3);
        etag[e] = etag[e + 1] = bi;
        e += 2;
      }
    }
    edgeRanges.push([start, e - start]);
  });
  const faces = new THREE.BufferGeometry();
  faces.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  faces.setAttribute('normal', new THREE.BufferAttribute(nrm, 3));
  faces.setAttribute('color', new THREE.BufferAttribute(col, 3));
  faces.setAttribute('pdBody', new THREE.BufferAttribute(tag, 1));
  const edges = new THREE.BufferGeometry();
  edges.setAttribute('position', new THREE.BufferAttribute(epos.subarray(0, e * 3), 3));
  edges.setAttribute('pdBody', new THREE.BufferAttribute(etag.subarray(0, e), 1));
  return { faces, edges, edgeRanges };
}

// Contact points and force arrows of one run at one sample (line segments p → p + F·scale).
class ContactLayer {
  constructor(run, color) {
    this.run = run;
    let most = 0;
    for (let s = 0; s + 1 < run.contactStart.length; ++s) most = Math.max(most, run.contactStart[s + 1] - run.contactStart[s]);
    this.capacity = Math.max(1, most);
    const lines = new THREE.BufferGeometry();
    this.linePos = new Float32Array(this.capacity * 6);
    this.lineCol = new Float32Array(this.capacity * 6);
    lines.setAttribute('position', new THREE.BufferAttribute(this.linePos, 3));
    lines.setAttribute('color', new THREE.BufferAttribute(this.lineCol, 3));
    const points = new THREE.BufferGeometry();
    this.pointPos = new Float32Array(this.capacity * 3);
    this.pointCol = new Float32Array(this.capacity * 3);
    points.setAttribute('position', new THREE.BufferAttribute(this.pointPos, 3));
    points.setAttribute('color', new THREE.BufferAttribute(this.pointCol, 3));
    this.group = new THREE.Group();
    this.lines = new THREE.LineSegments(lines, new THREE.LineBasicMaterial({ vertexColors: true, depthTest: false, transparent: true }));
    this.points = new THREE.Points(points, new THREE.PointsMaterial({ size: 6, sizeAttenuation: false, vertexColors: true, depthTest: false, transparent: true }));
    this.lines.renderOrder = this.points.renderOrder = 10;
    this.lines.frustumCulled = this.points.frustumCulled = false;
    this.group.add(this.lines, this.points);
    // stick and slip in the first run's colours; a ghost run's contacts in its key colour
    this.stick = new THREE.Color(color ? color : 0x00c0ff);
    this.slip = new THREE.Color(color ? color : 0xff3090);
    this.count = 0;
  }

  show(sample, scale) {
    const r = this.run, from = r.contactStart[sample], to = r.contactStart[sample + 1];
    const F = r.contactFloat, I = r.contactInt;
    let n = 0;
    for (let c = from; c < to; ++c, ++n) {
      const f = 6 * c, col = (I[3 * c + 2] & 2) ? this.slip : this.stick;
      this.pointPos.set([F[f], F[f + 1], F[f + 2]], 3 * n);
      this.linePos.set([F[f], F[f + 1], F[f + 2], F[f] + scale * F[f + 3], F[f + 1] + scale * F[f + 4], F[f + 2] + scale * F[f + 5]], 6 * n);
      this.pointCol.set([col.r, col.g, col.b], 3 * n);
      this.lineCol.set([col.r, col.g, col.b, col.r, col.g, col.b], 6 * n);
    }
    this.count = n;
    this.lines.geometry.setDrawRange(0, 2 * n);
    this.points.geometry.setDrawRange(0, n);
    for (const g of [this.lines.geometry, this.points.geometry])
      for (const a of Object.values(g.attributes)) a.needsUpdate = true;
  }
}

export const KEY_COLORS = ['#e8e8e8', '#ff8c1a', '#19b5ff', '#c04dff', '#3ccf4e', '#ffd21a', '#ff4d6a'];

export class SceneView {
  constructor(container, runs) {
    this.runs = runs;
    const bodies = runs[0].bodies;
    this.bodies = bodies;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: false });
    this.basePixelRatio = Math.min(window.devicePixelRatio || 1, 2);
    this.quality = 1;  // fraction of the base pixel ratio rendered (lowered while playing when frames are slow)
    this.renderer.setPixelRatio(this.basePixelRatio);
    this.renderer.setClearColor(0x20242b);
    container.appendChild(this.renderer.domElement);
    this.canvas = this.renderer.domElement;
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.enableDamping = false;

    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x404048, 1.1));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(0.6, -1, 1.6);
    this.scene.add(sun);
    const fill = new THREE.DirectionalLight(0xffffff, 0.5);
    fill.position.set(-1, 0.8, 0.4);
    this.scene.add(fill);

    this.colors = bodies.map((b) => sceneColor(b.color));
    const geo = buildGeometry(bodies, this.colors);
    this.edgeRanges = geo.edgeRanges;
    this.edgesGeometry = geo.edges;
    this.layers = runs.map((run, i) => {
      const pose = new PoseTexture(bodies.length);
      const ghost = i > 0;
      const key = new THREE.Color(KEY_COLORS[i % KEY_COLORS.length]);
      const solidMat = posed(ghost
        ? new THREE.MeshPhongMaterial({ color: key, transparent: true, opacity: 0.28, depthWrite: false, shininess: 40 })
        : new THREE.MeshPhongMaterial({ vertexColors: true, shininess: 40, specular: 0x333333, flatShading: true,
          polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 }), pose, true);
      const solid = new THREE.Mesh(geo.faces, solidMat);
      const edgeMat = posed(new THREE.LineBasicMaterial({
        color: ghost ? key : 0x111111, transparent: true, opacity: ghost ? 0.9 : 0.35 }), pose, false);
      const edges = new THREE.LineSegments(geo.edges, edgeMat);
      const wireMat = posed(new THREE.LineBasicMaterial({ color: ghost ? key : 0xffffff }), pose, false);
      const wire = new THREE.LineSegments(geo.edges, wireMat);
      // a wireframe of the first run shows each body in its scene colour
      if (!ghost) {
        const ecol = new Float32Array(geo.edges.attributes.pdBody.count * 3);
        geo.edges.attributes.pdBody.array.forEach((b, v) => ecol.set([this.colors[b].r, this.colors[b].g, this.colors[b].b], 3 * v));
        const wireGeometry = geo.edges.clone();
        wireGeometry.setAttribute('color', new THREE.BufferAttribute(ecol, 3));
        wire.geometry = wireGeometry;
        wireMat.vertexColors = true;
      }
      for (const o of [solid, edges, wire]) { o.frustumCulled = false; o.renderOrder = ghost ? 2 : 0; }
      const group = new THREE.Group();
      group.add(solid, edges, wire);
      this.scene.add(group);
      const contacts = new ContactLayer(run, ghost ? key : null);
      this.scene.add(contacts.group);
      // fixed bodies: their pose never changes; a ghost run does not draw them again
      const rows = new Float32Array(12);
      bodies.forEach((b, bi) => {
        if (!b.fixed) return;
        poseRows(b.x[0], b.x[1], b.x[2], b.q[0], b.q[1], b.q[2], b.q[3], rows, 0);
        if (ghost) rows.fill(0);  // a zero matrix collapses the body to a point: not drawn
        pose.set(bi, rows, 0);
      });
      return { run, pose, solid, edges, wire, group, contacts, key, visible: true };
    });

    // the selected body's edges, highlighted
    this.highlight = new THREE.LineSegments(new THREE.BufferGeometry(),
      posed(new THREE.LineBasicMaterial({ color: 0xffe14d }), this.layers[0].pose, false));
    this.highlight.frustumCulled = false;
    this.highlight.renderOrder = 5;
    this.scene.add(this.highlight);

    this.wireframe = false;
    this.showContacts = true;
    this.forceScale = 0;
    this.sceneSize = this.computeBounds();
    const fmax = Math.max(...runs.map((r) => r.forceScale()));
    this.forceScale = fmax > 0 ? 0.15 * this.sceneSize / fmax : 0;  // m per N
    this.follow = -1;
    this.tmp = new Float64Array(7);
    this.rows = new Float32Array(12);
    this.fit();
  }

  // Bounding box of the moving bodies over the whole run (fixed ones when nothing moves); its size, m.
  computeBounds() {
    const run = this.runs[0], box = new THREE.Box3();
    const m = run.moving.length;
    if (m) {
      const P = run.pose, S = run.t.length, step = Math.max(1, Math.floor(S / 200));
      for (let s = 0; s < S; s += step) for (let k = 0; k < m; ++k) {
        const i = (s * m + k) * 7, r = this.bodies[run.moving[k]].size;
        box.expandByPoint(new THREE.Vector3(P[i] - r, P[i + 1] - r, P[i + 2] - r));
        box.expandByPoint(new THREE.Vector3(P[i] + r, P[i + 1] + r, P[i + 2] + r));
      }
    } else {
      this.bodies.forEach((b) => {
        box.expandByPoint(new THREE.Vector3(b.x[0] - b.size, b.x[1] - b.size, b.x[2] - b.size));
        box.expandByPoint(new THREE.Vector3(b.x[0] + b.size, b.x[1] + b.size, b.x[2] + b.size));
      });
    }
    this.bounds = box;
    return Math.max(1e-3, box.getSize(new THREE.Vector3()).length());
  }

  fit() {
    const c = this.bounds.getCenter(new THREE.Vector3());
    const d = 0.65 * this.sceneSize / (2 * Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2)));
    const dir = new THREE.Vector3(0.55, -1, 0.55).normalize();
    this.camera.position.copy(c).addScaledVector(dir, d);
    this.camera.near = d / 1000;
    this.camera.far = d * 100;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(c);
    this.controls.update();
    this.follow = -1;
  }

  // Renders at `quality` × the device's pixel ratio (fewer pixels when a software renderer is slow).
  setQuality(quality) {
    if (quality === this.quality) return;
    this.quality = quality;
    this.renderer.setPixelRatio(this.basePixelRatio * quality);
    if (this.size) this.renderer.setSize(this.size[0], this.size[1], false);
  }

  resize(width, height) {
    this.size = [width, height];
    this.renderer.setSize(width, height, false);
    this.canvas.style.width = `${width}px`;
    this.canvas.style.height = `${height}px`;
    this.camera.aspect = width / Math.max(1, height);
    this.camera.updateProjectionMatrix();
  }

  // Poses of every moving body of every visible run at time t, and their contacts.
  setTime(t) {
    for (const L of this.layers) {
      const run = L.run;
      const [k, a] = run.locate(t);
      const m = run.moving.length;
      for (let s = 0; s < m; ++s) {
        const p = interpolatePose(run, s, k, a, this.tmp);
        poseRows(p[0], p[1], p[2], p[3], p[4], p[5], p[6], this.rows, 0);
        L.pose.set(run.moving[s], this.rows, 0);
      }
      L.pose.changed();
      const nearest = a < 0.5 ? k : k + 1;
      L.contacts.show(nearest, this.forceScale);
      L.sample = nearest;
    }
    if (this.follow >= 0) {
      const r = this.layers[0].pose.rows, b = this.follow;
      const target = new THREE.Vector3(r[b * 12 + 3], r[b * 12 + 7], r[b * 12 + 11]);
      const delta = target.clone().sub(this.controls.target);
      this.camera.position.add(delta);
      this.controls.target.copy(target);
      this.controls.update();
    }
  }

  applyVisibility() {
    for (const L of this.layers) {
      L.group.visible = L.visible;
      L.solid.visible = !this.wireframe;
      L.edges.visible = !this.wireframe;
      L.wire.visible = this.wireframe;
      L.contacts.group.visible = L.visible && this.showContacts;
    }
  }

  select(b) {
    this.selected = b;
    if (b < 0) {
      this.highlight.visible = false;
      return;
    }
    const [start, count] = this.edgeRanges[b];
    const g = new THREE.BufferGeometry();
    const src = this.edgesGeometry.attributes;
    g.setAttribute('position', new THREE.BufferAttribute(src.position.array.slice(start * 3, (start + count) * 3), 3));
    g.setAttribute('pdBody', new THREE.BufferAttribute(src.pdBody.array.slice(start, start + count), 1));
    this.highlight.geometry.dispose();
    this.highlight.geometry = g;
    this.highlight.visible = true;
  }

  // The body under canvas pixel (x, y) in the first run, or -1: the ray clipped by each body's faces.
  pick(x, y) {
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2((x / rect.width) * 2 - 1, -(y / rect.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    const o = ray.ray.origin, d = ray.ray.direction;
    const R = this.layers[0].pose.rows;
    let best = -1, bestT = Infinity;
    this.bodies.forEach((b, bi) => {
      const r = bi * 12;
      if (R[r] === 0 && R[r + 5] === 0 && R[r + 10] === 0) return;
      // ray in the body frame: Rᵀ (o − x), Rᵀ d
      const ox = o.x - R[r + 3], oy = o.y - R[r + 7], oz = o.z - R[r + 11];
      const lo = [R[r] * ox + R[r + 4] * oy + R[r + 8] * oz, R[r + 1] * ox + R[r + 5] * oy + R[r + 9] * oz, R[r + 2] * ox + R[r + 6] * oy + R[r + 10] * oz];
      const ld = [R[r] * d.x + R[r + 4] * d.y + R[r + 8] * d.z, R[r + 1] * d.x + R[r + 5] * d.y + R[r + 9] * d.z, R[r + 2] * d.x + R[r + 6] * d.y + R[r + 10] * d.z];
      let t0 = 0, t1 = bestT;
      const V = b.vertices;
      for (const f of b.faces) {
        // outward plane n·p = c of the face
        const [nx, ny, nz] = faceNormal(V, f);
        const c = nx * V[f[0] * 3] + ny * V[f[0] * 3 + 1] + nz * V[f[0] * 3 + 2];
        const num = c - (nx * lo[0] + ny * lo[1] + nz * lo[2]), den = nx * ld[0] + ny * ld[1] + nz * ld[2];
        if (den === 0) { if (num < 0) { t0 = Infinity; break; } continue; }
        const t = num / den;
        if (den < 0) t0 = Math.max(t0, t); else t1 = Math.min(t1, t);
        if (t0 > t1) break;
      }
      if (t0 <= t1 && t0 < bestT) { bestT = t0; best = bi; }
    });
    return best;
  }

  render() { this.renderer.render(this.scene, this.camera); }

  dispose() {
    this.controls.dispose();
    this.renderer.dispose();
    this.renderer.forceContextLoss();
    this.canvas.remove();
  }
}
