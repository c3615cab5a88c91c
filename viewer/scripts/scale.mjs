// Scale of the replay: a run of N bodies × T s at 100 samples/s (default 1000 × 10 s), made by polydyn
// itself (a scene of N spinning cubes thrown up in free flight: no contacts), written by polydyn view,
// opened and played in headless Chromium. Appends one row to reports/viewer/scale.csv.
//
// usage: node viewer/scripts/scale.mjs POLYDYN_BINARY [--bodies N] [--tend T] [--repeats R] [--csv FILE]
//                                      [--keep DIR]
//
// Measured: the time of polydyn view (reading the CSV, writing the page), the page's size, the load time
// (navigation start → first frame drawn, pdViewer.loadMs; median of R fresh pages), and, while playing
// at 1× for 5 s, the frames drawn per second, the main thread's time per frame (update + draw calls) and
// the render quality the viewer settled at (fraction of the device pixel ratio; see Replay.adaptQuality),
// with the machine's load average (the machine is shared: WebGL runs on SwiftShader, on the CPU).
import { execFileSync } from 'node:child_process';
import { appendFileSync, existsSync, mkdtempSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { loadavg, tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { launch } from './browser.mjs';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '../..');
const args = process.argv.slice(2);
const option = (name, fallback) => { const i = args.indexOf(name); return i >= 0 ? args.splice(i, 2)[1] : fallback; };
const bodies = Number(option('--bodies', 1000)), tend = Number(option('--tend', 10));
const repeats = Number(option('--repeats', 3));
const keep = option('--keep', null);  // a directory to keep the run and the page in
const csv = resolve(option('--csv', join(root, 'reports/viewer/scale.csv')));
const polydyn = resolve(args[0] ?? join(root, 'build/cli/polydyn'));
const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
const pct = (xs, p) => [...xs].sort((a, b) => a - b)[Math.min(xs.length - 1, Math.floor(p * xs.length))];

const scratch = keep ? resolve(keep) : mkdtempSync(join(tmpdir(), 'pd_viewer_scale.'));
try {
  // N cubes 0.1 m on a grid 0.5 m apart, thrown up at 49 m/s (back down at 10 s), each spinning
  let scene = `tend ${tend}\nsample 100\n`;
  const side = Math.ceil(Math.cbrt(bodies));
  for (let i = 0; i < bodies; ++i) {
    const x = i % side, y = Math.floor(i / side) % side, z = Math.floor(i / (side * side));
    scene += `cube c${i} ${['red', 'orange', 'gold', 'seagreen', 'steelblue', 'orchid'][i % 6]} 0.1 0.1 0.1\n`;
    scene += `loc ${0.5 * x} ${0.5 * y} ${0.5 * z} ${(37 * i) % 90} 1 0 0\n`;
    scene += `vel ${0.05 * (x - side / 2)} ${0.05 * (y - side / 2)} 49 ${90 + (i % 7) * 30} ${1 + (i % 3)} 1 0\n`;
  }
  writeFileSync(join(scratch, 'scale.scene'), scene);
  const run = join(scratch, 'run'), page = join(scratch, 'scale.html');
  let t = performance.now();
  execFileSync(polydyn, ['run', join(scratch, 'scale.scene'), '--out', run], { stdio: 'inherit' });
  const runSeconds = (performance.now() - t) / 1000;
  t = performance.now();
  execFileSync(polydyn, ['view', run, '-o', page], { stdio: 'inherit' });
  const viewSeconds = (performance.now() - t) / 1000;
  const csvBytes = statSync(join(run, 'trajectory.csv')).size, htmlBytes = statSync(page).size;

  const browser = await launch();
  const loads = [];
  let play = null, version = '';
  try {
    version = browser.context.browser()?.version() ?? '';
    for (let r = 0; r < repeats; ++r) {
      const tab = await browser.context.newPage();
      await tab.goto(pathToFileURL(page).href, { timeout: 120000 });
      loads.push(await tab.evaluate(async () => { await window.pdViewer.ready; return window.pdViewer.loadMs; }));
      if (r === repeats - 1) {
        // play at 1× for 5 s of wall time; count drawn frames and the main thread's time per frame
        play = await tab.evaluate(async () => {
          const v = window.pdViewer.main;
          v.frameTimes.length = 0;
          const ticks = [];
          let on = true;
          const tick = (now) => { ticks.push(now); if (on) requestAnimationFrame(tick); };
          requestAnimationFrame(tick);
          const t0 = v.t;
          v.play();
          await new Promise((res) => setTimeout(res, 5000));
          on = false;
          v.pause();
          const gaps = ticks.slice(1).map((x, i) => x - ticks[i]);
          return { quality: v.scene.quality, timings: v.timings, simulated: v.t - t0, frames: ticks.length, seconds: (ticks[ticks.length - 1] - ticks[0]) / 1000, gaps, work: [...v.frameTimes] };
        });
      }
      await tab.close();
    }
  } finally {
    await browser.close();
  }
  const fps = (play.frames - 1) / play.seconds;
  const row = {
    date: new Date().toISOString().slice(0, 10),
    commit: execFileSync('git', ['-C', root, 'rev-parse', '--short', 'HEAD']).toString().trim() +
      (execFileSync('git', ['-C', root, 'status', '--porcelain', '--', 'viewer', 'cli']).toString().trim() ? '+dirty' : ''),
    chromium: version, bodies, samples: Math.round(tend * 100) + 1, trajectory_mb: (csvBytes / 1e6).toFixed(1),
    html_mb: (htmlBytes / 1e6).toFixed(1), run_s: runSeconds.toFixed(2), view_s: viewSeconds.toFixed(2),
    load_ms_median: median(loads).toFixed(0), load_ms_max: Math.max(...loads).toFixed(0),
    fps: fps.toFixed(1), frame_gap_ms_p95: pct(play.gaps, 0.95).toFixed(1),
    frame_work_ms_median: median(play.work).toFixed(2), frame_work_ms_p95: pct(play.work, 0.95).toFixed(2),
    simulated_s_in_5s: play.simulated.toFixed(2), render_quality: play.quality.toFixed(2),
    decode_ms: play.timings.decode.toFixed(0), build_ms: play.timings.build.toFixed(0), parsed_ms: play.timings.start.toFixed(0),
    loadavg_1min: loadavg()[0].toFixed(2),
  };
  if (!existsSync(csv)) appendFileSync(csv, `${Object.keys(row).join(',')}\n`);
  appendFileSync(csv, `${Object.values(row).join(',')}\n`);
  console.log(row);
} finally {
  if (!keep) rmSync(scratch, { recursive: true, force: true });
}
