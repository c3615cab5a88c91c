// The replay page in headless Chromium (Debian's, driven by playwright-core) and the movie command.
//
// usage: node tests/viewer/browser.test.mjs POLYDYN_BINARY PROJECT_SOURCE_DIR [REPORT_PAGE]
// REPORT_PAGE: the two-replay page test_view_page writes through the C API (a report's way).
// Exit 77 (skipped) only when Chromium is not installed.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [polydyn, source, reportPage] = process.argv.slice(2).map((p) => resolve(p));
if (!polydyn || !source) {
  console.error('usage: browser.test.mjs POLYDYN_BINARY PROJECT_SOURCE_DIR');
  process.exit(2);
}
const { launch, haveChromium, chromiumPath, viewStats } = await import(join(source, 'viewer/scripts/browser.mjs'));
if (!haveChromium()) {
  console.log(`SKIP: no Chromium at ${chromiumPath}`);
  process.exit(77);
}

const TOL = 1e-6;  // drawn pose against trajectory.csv (the GPU gets float32: ~1e-7 at these sizes)
const scratch = mkdtempSync(join(tmpdir(), 'pd_test_viewer.'));
const demo = join(source, 'cases/examples/demo.scene');
let browser, page;
const requests = [];
const pageErrors = [];

function polydynRun(...args) {
  return execFileSync(polydyn, args, { stdio: ['ignore', 'pipe', 'pipe'] }).toString();
}

// trajectory.csv rows of one body: [{ t, x: [3], q: [4] }] (no quoted names in the demo)
function trajectory(dir, body) {
  return readFileSync(join(dir, 'trajectory.csv'), 'utf8').trim().split('\n').slice(1)
    .map((line) => line.split(','))
    .filter((f) => f[1] === body)
    .map((f) => ({ t: Number(f[0]), x: f.slice(2, 5).map(Number), q: f.slice(5, 9).map(Number) }));
}

// the 3×4 rows [R | x] for a pose, R from the unit quaternion (w, x, y, z)
function poseRows({ x: p, q: [w, x, y, z] }) {
  return [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y), p[0],
    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x), p[1],
    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y), p[2]];
}

function maxDiff(a, b) { return Math.max(...a.map((v, i) => Math.abs(v - b[i]))); }

// Statistics of the 3-D view's pixels in a screenshot: share differing from the clear colour, colours.
function viewPixels() { return viewStats(page, page.locator('.pdv-view canvas')); }

// A new tab on the page `file`, after its main replay is ready; `errors` collects page errors and, with
// consoleErrors, console errors.
async function openTab(file, { consoleErrors = true } = {}) {
  const tab = await browser.context.newPage();
  const errors = [];
  tab.on('pageerror', (e) => errors.push(e.message));
  if (consoleErrors) tab.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await tab.goto(pathToFileURL(file).href);
  await tab.evaluate(() => window.pdViewer.ready);
  return { tab, errors };
}

// A run directory's files as a report hands them to PolydynViewer.mount.
function runFiles(dir, name) {
  return {
    run: name,
    summary: JSON.parse(readFileSync(join(dir, 'summary.json'), 'utf8')),
    trajectory: readFileSync(join(dir, 'trajectory.csv'), 'utf8'),
    contacts: readFileSync(join(dir, 'contacts.csv'), 'utf8'),
  };
}

const runA = join(scratch, 'demo');      // 100 samples/s
const runB = join(scratch, 'demo-50');   // the same scene at 50 samples/s: the ghost overlay
const pagePath = join(scratch, 'demo.html');

before(async () => {
  polydynRun('run', demo, '--out', runA, '--tend', '1');
  polydynRun('run', demo, '--out', runB, '--tend', '1', '--sample', '50');
  polydynRun('view', runA, runB, '-o', pagePath);
  browser = await launch();
  page = await browser.context.newPage();
  page.on('request', (r) => requests.push(r.url()));
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(pathToFileURL(pagePath).href);
  await page.evaluate(() => window.pdViewer.ready);
});

after(async () => {
  await browser?.close();
  rmSync(scratch, { recursive: true, force: true });
});

test('the page opens from disk without a request to anything but itself, and without errors', () => {
  const others = requests.filter((u) => !u.startsWith('file:') && !u.startsWith('data:'));
  assert.deepEqual(others, []);
  assert.deepEqual(pageErrors, []);
});

test('after play, the drawn pose of box follows trajectory.csv at two sample times within 1e-6', async () => {
  const rows = trajectory(runA, 'box');
  await page.click('.pdv-play');
  await page.waitForTimeout(400);
  await page.click('.pdv-play');  // pause
  const played = await page.evaluate(() => window.pdViewer.main.t);
  assert.ok(played > 0, `playing moved the time (t = ${played})`);
  const checked = [];
  for (const pass of [0, 1]) {
    if (pass === 1) {
      // the other half of the run from the first check (playing may have looped on a busy machine)
      const seek = checked[0].t < 0.5 ? 0.73 : 0.23;
      // scrub: the timeline is 0…100000 over [t0, t1]
      await page.locator('.pdv-timeline').fill(String(Math.round(seek * 100000)));
    }
    await page.click('.pdv-next');  // to the next sample
    const { t, m, label } = await page.evaluate(() => {
      const v = window.pdViewer.main;
      v.renderNow();
      return { t: v.t, m: v.bodyMatrix(0, 'box'), label: document.querySelector('.pdv-time').textContent };
    });
    const row = rows.find((r) => r.t === t);
    assert.ok(row, `t = ${t} is a sample of trajectory.csv`);
    const diff = maxDiff(m.slice(0, 12), poseRows(row));
    assert.ok(diff <= TOL, `drawn pose at t = ${t} differs by ${diff} (tolerance ${TOL})`);
    assert.match(label, new RegExp(`t = ${t.toFixed(4)} s · sample ${Math.round(t * 100)} `));
    checked.push({ t, m });
  }
  assert.ok(Math.abs(checked[1].t - checked[0].t) > 0.1, `two different times (${checked[0].t}, ${checked[1].t})`);
  assert.ok(maxDiff(checked[0].m, checked[1].m) > 1e-3, 'the box moved between them');
});

test('between two samples the drawn position is their linear interpolation (1e-6)', async () => {
  const rows = trajectory(runA, 'box');
  const [a, b] = [rows[37], rows[38]];
  const m = await page.evaluate((t) => { window.pdViewer.setTime(t); return window.pdViewer.main.bodyMatrix(0, 'box'); },
    0.25 * a.t + 0.75 * b.t);
  const expected = a.x.map((x, i) => 0.25 * x + 0.75 * b.x[i]);
  assert.ok(maxDiff([m[3], m[7], m[11]], expected) <= TOL);
});

test('the ghost run (50 samples/s) is drawn at its own samples', async () => {
  const rows = trajectory(runB, 'cone');
  const m = await page.evaluate((t) => { window.pdViewer.setTime(t); return window.pdViewer.main.bodyMatrix(1, 'cone'); }, rows[20].t);
  assert.ok(maxDiff(m.slice(0, 12), poseRows(rows[20])) <= TOL);
});

test('the screenshot of the 3-D view is not blank', async () => {
  await page.evaluate(() => { window.pdViewer.setTime(0.5); });
  const s = await viewPixels();
  assert.ok(s.drawn > 0.05, `${(100 * s.drawn).toFixed(1)} % of the view is drawn`);
  assert.ok(s.colours > 50, `${s.colours} colours`);
});

test('the wireframe toggle and the overlay toggle change what is drawn', async () => {
  await page.evaluate(() => { window.pdViewer.setTime(0.5); });
  const solid = await viewPixels();
  await page.click('.pdv-wireframe');
  const state = await page.evaluate(() => {
    const L = window.pdViewer.main.scene.layers;
    window.pdViewer.main.renderNow();
    return { wire: L[0].wire.visible, solid: L[0].solid.visible };
  });
  assert.deepEqual(state, { wire: true, solid: false });
  const wire = await viewPixels();
  const changed = (a, b) => a.data.filter((v, i) => Math.abs(v - b.data[i]) > 8).length / a.data.length;
  assert.ok(changed(solid, wire) > 0.01, `wireframe changed ${(100 * changed(solid, wire)).toFixed(2)} % of the samples`);
  await page.click('.pdv-wireframe');

  await page.click('.pdv-run-1');
  const ghostHidden = await page.evaluate(() => { window.pdViewer.main.renderNow(); return window.pdViewer.main.scene.layers[1].group.visible; });
  assert.equal(ghostHidden, false);
  const noGhost = await viewPixels();
  assert.ok(changed(solid, noGhost) > 0.0005, `hiding the ghost changed ${(100 * changed(solid, noGhost)).toFixed(3)} % of the samples`);
  await page.click('.pdv-run-1');
});

test('clicking a body selects it for the plot', async () => {
  // the box's centre on screen, from the camera: pick it there
  const name = await page.evaluate(() => {
    const v = window.pdViewer.main, m = v.bodyMatrix(0, 'box');
    const THREE_Vector = v.scene.camera.position.constructor;
    const p = new THREE_Vector(m[3], m[7], m[11]).project(v.scene.camera);
    const r = v.scene.canvas.getBoundingClientRect();
    const b = v.scene.pick((p.x + 1) / 2 * r.width, (1 - p.y) / 2 * r.height);
    v.selectBody(b);
    return v.runs[0].bodies[b]?.name;
  });
  assert.equal(name, 'box');
});

test('polydyn view --movie makes an MP4 of N = floor(T·fps/speed) + 1 frames lasting N/fps', () => {
  const movie = join(scratch, 'demo.mp4');
  const fps = 10, speed = 2;  // 1 s of simulation → 6 frames, 0.6 s
  const r = spawnSync(polydyn, ['view', runA, '--movie', movie, '--fps', String(fps), '--speed', String(speed)], { encoding: 'utf8' });
  assert.equal(r.status, 0, r.stderr);
  assert.ok(existsSync(movie));
  const probe = JSON.parse(execFileSync('ffprobe', ['-v', 'error', '-count_frames', '-show_entries',
    'format=duration:stream=nb_read_frames,codec_name,width,height', '-of', 'json', movie]).toString());
  const frames = Math.floor((1 * fps) / speed) + 1;
  assert.equal(Number(probe.streams[0].nb_read_frames), frames);
  assert.ok(Math.abs(Number(probe.format.duration) - frames / fps) <= 1 / fps, `duration ${probe.format.duration} s`);
  assert.equal(probe.streams[0].width, 1280);
});

test('a report page with two replays shares one bundle and opens each replay on a click', { skip: !reportPage && 'no report page given' }, async () => {
  const { tab, errors } = await openTab(reportPage, { consoleErrors: false });
  assert.equal(await tab.locator('script:not([type])').count(), 1);
  assert.equal(await tab.locator('button.pdv-open').count(), 2);
  assert.deepEqual(await tab.evaluate(() => Object.keys(window.pdViewer.replays)), []);
  await tab.locator('#pd-replay-exp2 button.pdv-open').click();
  await tab.locator('#pd-replay-exp1 button.pdv-open').click();
  await tab.waitForFunction(() => Object.keys(window.pdViewer.replays).length === 2);
  const r = await tab.evaluate(() => {
    const v = window.pdViewer.replays.exp2;
    v.setTime(0.3);
    v.renderNow();
    return { runs: v.runs.map((x) => x.engine), m: v.bodyMatrix(1, 'cube'), canvases: document.querySelectorAll('.pdv-view canvas').length };
  });
  assert.deepEqual(r.runs, ['polydyn-soft', 'ode']);
  assert.equal(r.canvases, 2);
  // test_view_page.c: x = 0.1 k + 1/3, z = 1 − 0.05 k at t = 0.1 k
  assert.ok(Math.abs(r.m[3] - (0.3 + 1 / 3)) <= TOL && Math.abs(r.m[11] - 0.85) <= TOL);
  assert.deepEqual(errors, []);
  await tab.close();
});

test('PolydynViewer.mount (the report hook) builds from the CSV texts the same run the page embeds, and draws', async () => {
  const { tab, errors } = await openTab(pagePath);
  const files = runFiles(runA, 'demo');
  const r = await tab.evaluate((files) => {
    const div = document.createElement('div');
    document.body.prepend(div);
    const v = window.PolydynViewer.mount(div, files), a = v.runs[0], b = window.pdViewer.main.runs[0];
    const same = ['t', 'pose', 'vel', 'contactStart', 'contactFloat', 'contactInt']
      .filter((k) => a[k].length !== b[k].length || a[k].some((x, i) => x !== b[k][i]));
    v.setTime(a.t[37]);
    v.renderNow();
    return { differ: same, contacts: a.contacts, m: v.bodyMatrix(0, 'box'), t: v.t, canvases: div.querySelectorAll('.pdv-view canvas').length };
  }, files);
  assert.deepEqual(r.differ, [], 'arrays equal to the embedded (C-read) ones');
  assert.ok(r.contacts > 0);
  assert.equal(r.canvases, 1);
  const row = trajectory(runA, 'box').find((x) => x.t === r.t);
  assert.ok(maxDiff(r.m.slice(0, 12), poseRows(row)) <= TOL);
  assert.deepEqual(errors, []);
  await tab.close();
});

test('PolydynViewer.mount with several runs (a cube toss and its engines in a report) overlays them as polydyn view does', async () => {
  const { tab, errors } = await openTab(pagePath);
  const r = await tab.evaluate((payload) => {
    const div = document.createElement('div');
    document.body.prepend(div);
    const v = window.PolydynViewer.mount(div, payload), main = window.pdViewer.main;
    const differ = v.runs.map((a, k) => ['t', 'pose', 'vel', 'contactStart', 'contactFloat', 'contactInt']
      .filter((key) => a[key].length !== main.runs[k][key].length || a[key].some((x, i) => x !== main.runs[k][key][i])));
    const t = v.runs[1].t[20];  // a sample of the 50/s run, between samples of neither
    v.setTime(t);
    v.renderNow();
    return { runs: v.runs.length, labels: v.runs.map((x) => x.label), differ, t,
      m0: v.bodyMatrix(0, 'box'), m1: v.bodyMatrix(1, 'box'),
      runLabels: Array.from(div.querySelectorAll('.pdv-runlabel')).map((l) => l.textContent) };
  }, { title: 'two runs', runs: [runFiles(runA, 'demo'), runFiles(runB, 'demo-50')] });
  assert.equal(r.runs, 2);
  assert.deepEqual(r.differ, [[], []], 'each run equal to the one polydyn view embedded');
  assert.notEqual(r.labels[0], r.labels[1], 'two runs of one engine are told apart by their directory');
  assert.equal(r.runLabels.length, 2);
  assert.match(r.runLabels[1], /ghost/);
  // both runs sample the same motion: at a sample time of the 50/s run the two draw the same pose
  const rowB = trajectory(runB, 'box').find((x) => x.t === r.t);
  assert.ok(maxDiff(r.m1.slice(0, 12), poseRows(rowB)) <= TOL);
  assert.ok(maxDiff(r.m0.slice(0, 12), poseRows(rowB)) <= TOL);
  assert.deepEqual(errors, []);
  await tab.close();
});
