// One replay: the 3-D view, the plot and the controls, for one run or several runs of one scene.
import { SceneView, KEY_COLORS } from './scene3d.js';
import { Plot, QUANTITIES, series } from './plot.js';
import { cssColor } from './colors.js';

const SPEED_MIN = -2, SPEED_MAX = 2;  // log10 of the playback speed: 1/100× … 100×

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v;
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (v !== false && v != null) e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children) e.append(c);
  return e;
}

function formatSpeed(s) {
  if (s >= 1) return `${+s.toPrecision(3)}×`;
  return `1/${+(1 / s).toPrecision(3)}×`;
}

export class Replay {
  constructor(root, data) {
    this.root = root;
    this.runs = data.runs;
    const runs = this.runs, first = runs[0];
    this.t0 = Math.min(...runs.map((r) => r.t0));
    this.t1 = Math.max(...runs.map((r) => r.t1));
    this.t = this.t0;
    this.speed = 1;
    this.playing = false;
    this.loop = true;
    this.quantity = 'height';
    this.frameTimes = [];

    const sceneName = first.scene.replace(/^.*\//, '').replace(/\.scene$/, '');
    const title = data.title || `${sceneName}: ${runs.map((r) => r.label).join(' vs ')}`;

    // controls
    this.playButton = el('button', { class: 'pdv-play', title: 'play / pause (space)', onclick: () => this.toggle() }, '▶');
    this.timeline = el('input', { type: 'range', min: 0, max: 100000, step: 1, value: 0, class: 'pdv-timeline', 'aria-label': 'time' });
    this.timeline.addEventListener('input', () => this.setTime(this.t0 + (this.timeline.value / 100000) * (this.t1 - this.t0)));
    this.timeLabel = el('span', { class: 'pdv-time' });
    this.speedInput = el('input', { type: 'range', min: SPEED_MIN, max: SPEED_MAX, step: 0.01, value: 0, class: 'pdv-speed', 'aria-label': 'speed' });
    this.speedInput.addEventListener('input', () => this.setSpeed(10 ** +this.speedInput.value));
    this.speedLabel = el('span', { class: 'pdv-speed-label' }, '1×');
    this.loopBox = el('input', { type: 'checkbox', checked: true, onchange: () => { this.loop = this.loopBox.checked; } });
    this.wireBox = el('input', { type: 'checkbox', class: 'pdv-wireframe', onchange: () => this.setWireframe(this.wireBox.checked) });
    this.contactBox = el('input', { type: 'checkbox', class: 'pdv-contacts', checked: true, onchange: () => this.setContacts(this.contactBox.checked) });
    this.bodySelect = el('select', { class: 'pdv-body', 'aria-label': 'body', onchange: () => this.selectBody(+this.bodySelect.value) },
      el('option', { value: -1 }, '(no body)'),
      ...first.bodies.map((b, i) => el('option', { value: i }, b.fixed ? `${b.name} (fixed)` : b.name)));
    this.followBox = el('input', { type: 'checkbox', class: 'pdv-follow', onchange: () => this.setFollow(this.followBox.checked) });
    this.quantitySelect = el('select', { class: 'pdv-quantity', 'aria-label': 'plotted quantity', onchange: () => { this.quantity = this.quantitySelect.value; this.updatePlot(); } },
      ...Object.entries(QUANTITIES).map(([k, q]) => el('option', { value: k }, k)));
    const runToggles = runs.map((r, i) => {
      const box = el('input', { type: 'checkbox', checked: true, class: `pdv-run pdv-run-${i}`, onchange: () => this.setRunVisible(i, box.checked) });
      const swatch = el('span', { class: i ? 'pdv-swatch' : 'pdv-swatch pdv-swatch-scene' });
      if (i) swatch.style.background = KEY_COLORS[i % KEY_COLORS.length];
      const note = r.completed ? '' : ' (stopped early)';
      return el('label', { class: 'pdv-runlabel', title: r.dir }, box, swatch, `${r.label}${i ? ', ghost' : ''}${note}`);
    });

    this.view = el('div', { class: 'pdv-view' });
    this.caption = el('div', { class: 'pdv-caption' });
    this.legend = el('div', { class: 'pdv-legend' });
    this.view.append(this.caption, this.legend);
    this.plotCanvas = el('canvas', { class: 'pdv-plot' });
    this.ui = el('div', { class: 'pdv' },
      el('div', { class: 'pdv-top' }, el('span', { class: 'pdv-title' }, title), el('span', { class: 'pdv-runs' }, ...runToggles),
        el('span', { class: 'pdv-info' }, this.describe())),
      this.view,
      this.plotCanvas,
      el('div', { class: 'pdv-bar' },
        el('button', { title: 'to the start (Home)', onclick: () => this.setTime(this.t0) }, '⇤'),
        el('button', { class: 'pdv-prev', title: 'previous sample (←)', onclick: () => this.step(-1) }, '◀︎|'),
        this.playButton,
        el('button', { class: 'pdv-next', title: 'next sample (→)', onclick: () => this.step(1) }, '|▶︎'),
        this.timeline, this.timeLabel),
      el('div', { class: 'pdv-bar' },
        el('label', { title: 'playback speed, 1/100× to 100× (− and +)' }, 'speed ', this.speedInput, this.speedLabel),
        el('label', {}, this.loopBox, 'loop'),
        el('label', { title: 'W' }, this.wireBox, 'wireframe'),
        el('label', { title: 'C' }, this.contactBox, 'contacts'),
        el('label', {}, 'body ', this.bodySelect),
        el('label', { title: 'the camera follows the selected body (double-click a body)' }, this.followBox, 'follow'),
        el('button', { title: 'show everything (F)', onclick: () => { this.followBox.checked = false; this.scene.fit(); this.dirty = true; } }, 'fit'),
        el('label', {}, 'plot ', this.quantitySelect)),
      el('div', { class: 'pdv-help' }, 'drag: orbit · right-drag or shift-drag: pan · wheel: zoom · click a body: select · double-click: follow · space: play · ←/→: step'));
    root.append(this.ui);

    this.scene = new SceneView(this.view, runs);
    this.plot = new Plot(this.plotCanvas);
    this.scene.controls.addEventListener('change', () => { this.dirty = true; });
    this.scene.applyVisibility();
    const forceNote = this.scene.forceScale > 0
      ? `force arrows: 0.1 m = ${+(0.1 / this.scene.forceScale).toPrecision(2)} N · stick ● slip ●` : 'no contacts recorded';
    this.legend.innerHTML = '';
    if (this.scene.forceScale > 0) {
      this.legend.append(`force arrows: 0.1 m = ${+(0.1 / this.scene.forceScale).toPrecision(2)} N · `,
        el('span', { style: 'color:#00c0ff' }, 'stick'), ' · ', el('span', { style: 'color:#ff3090' }, 'slip'));
    } else {
      this.legend.append(forceNote);
    }

    // picking: click selects, double-click follows
    let down = null;
    this.scene.canvas.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
    this.scene.canvas.addEventListener('click', (e) => {
      if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
      const r = this.scene.canvas.getBoundingClientRect();
      this.selectBody(this.scene.pick(e.clientX - r.left, e.clientY - r.top));
    });
    this.scene.canvas.addEventListener('dblclick', () => { if (this.selected >= 0) { this.followBox.checked = true; this.setFollow(true); } });
    this.plotCanvas.addEventListener('click', (e) => {
      const r = this.plotCanvas.getBoundingClientRect();
      this.setTime(this.plot.timeAt(e.clientX - r.left));
    });
    this.ui.tabIndex = 0;
    this.ui.addEventListener('keydown', (e) => this.onKey(e));

    this.resizeObserver = new ResizeObserver(() => this.resize());
    this.resizeObserver.observe(this.view);
    this.resize();
    // the heaviest moving body is the one plotted at first
    let pick = -1;
    first.bodies.forEach((b, i) => { if (!b.fixed && (pick < 0 || b.mass > first.bodies[pick].mass)) pick = i; });
    this.selectBody(pick);
    this.setTime(this.t0);
    this.last = null;
    this.frame = this.frame.bind(this);
    this.raf = requestAnimationFrame(this.frame);
  }

  // One line about what is replayed: bodies, time span, samples, contacts.
  describe() {
    const r = this.runs[0], fixed = r.bodies.filter((b) => b.fixed).length;
    const rate = r.t.length > 1 ? Math.round((r.t.length - 1) / (r.t1 - r.t0)) : 0;
    const contacts = r.hasContacts ? `${r.contacts.toLocaleString('en')} contact rows` : 'no contacts.csv';
    return `${r.bodies.length} bodies (${fixed} fixed) · t = ${r.t0}…${r.t1} s · ${r.t.length} samples (${rate}/s) · ${contacts}`;
  }

  onKey(e) {
    if (e.target.tagName === 'SELECT' || (e.target.tagName === 'INPUT' && e.target.type !== 'checkbox' && e.target.type !== 'range')) return;
    const k = e.key;
    if (k === ' ') this.toggle();
    else if (k === 'ArrowRight') this.step(1);
    else if (k === 'ArrowLeft') this.step(-1);
    else if (k === 'Home') this.setTime(this.t0);
    else if (k === 'End') this.setTime(this.t1);
    else if (k === '+' || k === '=') this.setSpeed(this.speed * 2);
    else if (k === '-') this.setSpeed(this.speed / 2);
    else if (k === 'w' || k === 'W') { this.wireBox.checked = !this.wireBox.checked; this.setWireframe(this.wireBox.checked); }
    else if (k === 'c' || k === 'C') { this.contactBox.checked = !this.contactBox.checked; this.setContacts(this.contactBox.checked); }
    else if (k === 'f' || k === 'F') { this.followBox.checked = false; this.scene.fit(); this.dirty = true; }
    else return;
    e.preventDefault();
  }

  resize() {
    const w = this.view.clientWidth, h = this.view.clientHeight;
    if (!w || !h) return;
    this.scene.resize(w, h);
    this.plot.redraw();
    this.dirty = true;
  }

  // --- state

  setTime(t) {
    this.t = Math.min(this.t1, Math.max(this.t0, t));
    this.scene.setTime(this.t);
    const run = this.runs[0], [k, a] = run.locate(this.t);
    this.sample = a < 0.5 ? k : k + 1;
    this.timeline.value = Math.round(((this.t - this.t0) / (this.t1 - this.t0 || 1)) * 100000);
    const atSample = a === 0 ? '' : ' ≈';
    this.timeLabel.textContent = `t = ${this.t.toFixed(4)} s · sample${atSample} ${this.sample} of 0…${run.t.length - 1}`;
    this.caption.textContent = `t = ${this.t.toFixed(3)} s   ${formatSpeed(this.speed)}`;
    this.plot.draw(this.t);
    this.dirty = true;
  }

  setSpeed(s) {
    this.speed = Math.min(10 ** SPEED_MAX, Math.max(10 ** SPEED_MIN, s));
    this.speedInput.value = Math.log10(this.speed);
    this.speedLabel.textContent = formatSpeed(this.speed);
    this.caption.textContent = `t = ${this.t.toFixed(3)} s   ${formatSpeed(this.speed)}`;
  }

  play() {
    if (this.t >= this.t1) this.setTime(this.t0);
    this.playing = true;
    this.last = null;
    this.playButton.textContent = '❚❚';
  }

  pause() {
    this.playing = false;
    this.playButton.textContent = '▶';
  }

  toggle() { if (this.playing) this.pause(); else this.play(); }

  // To the next (+1) or previous (−1) sample of the first run.
  step(dir) {
    this.pause();
    const run = this.runs[0], [k, a] = run.locate(this.t);
    const target = dir > 0 ? k + 1 : (a > 0 ? k : k - 1);
    this.setTime(run.t[Math.min(run.t.length - 1, Math.max(0, target))]);
  }

  setWireframe(on) { this.scene.wireframe = on; this.scene.applyVisibility(); this.dirty = true; }
  setContacts(on) { this.scene.showContacts = on; this.scene.applyVisibility(); this.dirty = true; }

  setRunVisible(i, on) {
    this.scene.layers[i].visible = on;
    const box = this.ui.querySelector(`.pdv-run-${i}`);
    if (box) box.checked = on;
    this.scene.applyVisibility();
    this.updatePlot();
    this.dirty = true;
  }

  setFollow(on) {
    this.scene.follow = on && this.selected >= 0 ? this.selected : -1;
    this.scene.setTime(this.t);
    this.dirty = true;
  }

  selectBody(b) {
    this.selected = b;
    this.bodySelect.value = b;
    this.scene.select(b);
    if (this.followBox.checked) this.setFollow(b >= 0);
    this.updatePlot();
    this.dirty = true;
  }

  updatePlot() {
    const b = this.selected, q = QUANTITIES[this.quantity];
    const lines = [];
    if (b >= 0) {
      this.runs.forEach((run, i) => {
        if (!this.scene.layers[i].visible) return;
        const y = series(run, b, this.quantity);
        if (y) lines.push({ color: i ? KEY_COLORS[i % KEY_COLORS.length] : cssColor(this.scene.colors[b]), t: run.t, y });
      });
    }
    const name = b >= 0 ? this.runs[0].bodies[b].name : '';
    this.plot.set(lines, this.t0, this.t1, b >= 0 ? `${name}: ${q.label}, ${q.unit}` : q.label, q.unit);
    this.plot.draw(this.t);
  }

  // --- the animation loop

  // While playing, the resolution follows the frame rate: below ~50 frames/s (a software renderer, a
  // weak GPU) fewer pixels are drawn, down to a third of the device's; a paused frame is drawn in full.
  adaptQuality(now) {
    const gaps = this.gaps || (this.gaps = []);
    if (!this.playing || this.movie) {
      gaps.length = 0;
      if (this.scene.quality !== 1) { this.scene.setQuality(1); this.dirty = true; }
      return;
    }
    if (this.last != null) gaps.push(now - this.last);
    if (gaps.length < 12) return;
    gaps.sort((a, b) => a - b);
    const typical = gaps[6];
    gaps.length = 0;
    const q = this.scene.quality;
    // a level found too slow is not tried again (no back and forth between two resolutions)
    if (typical > 20 && q > 0.34) {
      this.ceiling = q;
      // the pixels drawn go as quality²: aim at 60 frames/s in one step
      this.scene.setQuality(Math.max(0.34, Math.min(0.85 * q, 0.9 * q * Math.sqrt(16.7 / typical))));
    } else if (typical < 17.5 && q / 0.85 < (this.ceiling ?? 1.01)) {
      this.scene.setQuality(Math.min(1, q / 0.85));
    }
  }

  frame(now) {
    this.raf = requestAnimationFrame(this.frame);
    this.adaptQuality(now);
    if (this.playing) {
      const dt = this.last == null ? 0 : (now - this.last) / 1000;
      let t = this.t + dt * this.speed;
      if (t > this.t1) {
        if (this.loop) t = this.t0 + ((t - this.t0) % (this.t1 - this.t0 || 1));
        else { t = this.t1; this.pause(); }
      }
      this.setTime(t);
    }
    this.last = now;
    if (this.dirty) {
      const start = performance.now();
      this.scene.render();
      this.dirty = false;
      this.frameTimes.push(performance.now() - start);
      if (this.frameTimes.length > 600) this.frameTimes.shift();
    }
  }

  // Renders now (movies and tests call this after setTime).
  renderNow() {
    this.scene.render();
    this.dirty = false;
  }

  setMovieMode(on) {
    this.movie = on;
    this.scene.setQuality(1);
    this.ui.classList.toggle('pdv-movie', on);
    if (on) this.selectBody(-1);
    this.pause();
    this.resize();
  }

  // The drawn pose of body `name` in run `runIndex`: the 4×4 matrix (row-major) the GPU receives.
  bodyMatrix(runIndex, name) {
    const b = this.runs[0].bodies.findIndex((x) => x.name === name);
    if (b < 0) return null;
    const r = this.scene.layers[runIndex].pose.rows.subarray(b * 12, b * 12 + 12);
    return [...r, 0, 0, 0, 1];
  }

  dispose() {
    cancelAnimationFrame(this.raf);
    this.resizeObserver.disconnect();
    this.scene.dispose();
    this.ui.remove();
  }
}
