// Renders a page written by polydyn view into a movie: headless Chromium draws the replay at each
// frame's time (pdViewer.setTime, deterministic: no clock involved), ffmpeg encodes the screenshots.
// Called by `polydyn view DIR --movie OUT.mp4`; usable alone:
//   node viewer/scripts/movie.mjs --html PAGE.html --out OUT.mp4 [--fps 60] [--speed 1] [--size 1280x720]
// Frame k shows simulated time t0 + k·speed/fps, for k = 0 … N−1, N = ⌊(t1 − t0)·fps/speed⌋ + 1; the
// movie lasts N/fps seconds. H.264 (libx264) when ffmpeg has it, else MPEG-4 part 2.
import { spawn, spawnSync } from 'node:child_process';
import { rmSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { launch } from './browser.mjs';

function fail(message) {
  console.error(`movie: ${message}`);
  process.exit(1);
}

const args = process.argv.slice(2);
const opts = { fps: '60', speed: '1', size: '1280x720' };
for (let i = 0; i < args.length; i += 2) {
  const key = args[i].replace(/^--/, '');
  if (!['html', 'out', 'fps', 'speed', 'size'].includes(key) || i + 1 >= args.length) fail(`bad argument '${args[i]}'`);
  opts[key] = args[i + 1];
}
if (!opts.html || !opts.out) fail('usage: movie.mjs --html PAGE.html --out OUT.mp4 [--fps N] [--speed S] [--size WxH]');
const fps = Number(opts.fps), speed = Number(opts.speed);
const [width, height] = opts.size.split('x').map(Number);
if (!(fps > 0) || !(speed > 0) || !(width > 0) || !(height > 0)) fail('fps, speed and size must be positive');

const ffmpeg = process.env.POLYDYN_FFMPEG || 'ffmpeg';
const encoders = spawnSync(ffmpeg, ['-hide_banner', '-encoders'], { encoding: 'utf8' });
if (encoders.error) fail(`cannot run ${ffmpeg}: ${encoders.error.message}`);
const codec = /\blibx264\b/.test(encoders.stdout)
  ? ['-c:v', 'libx264', '-preset', 'veryfast', '-crf', '20', '-pix_fmt', 'yuv420p']
  : ['-c:v', 'mpeg4', '-q:v', '3', '-pix_fmt', 'yuv420p'];

const browser = await launch();
let encoder = null, encoderDone = null;

// Stops ffmpeg, removes the unfinished movie and the browser's profile, exits with `code`. The first
// call wins: on Ctrl-C the browser dies too, and the failed screenshot that follows is not the news.
let abandoning = null;
function abandon(code, message) {
  abandoning ??= (async () => {
    if (message) console.error(`movie: ${message.split('\n')[0]}`);
    if (encoder && encoder.exitCode === null) encoder.kill('SIGKILL');
    await encoderDone;
    rmSync(opts.out, { force: true });
    await browser.close().catch(() => {});
    process.exit(code);
  })();
  return abandoning;
}
for (const signal of ['SIGINT', 'SIGTERM']) process.on(signal, () => abandon(130, 'interrupted'));

try {
  const page = await browser.context.newPage();
  await page.setViewportSize({ width, height });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(pathToFileURL(resolve(opts.html)).href);
  const range = await page.evaluate(async () => {
    const v = await window.pdViewer.ready;
    v.setMovieMode(true);
    return [v.t0, v.t1];
  });
  const [t0, t1] = range;
  const frames = Math.floor(((t1 - t0) * fps) / speed + 1e-9) + 1;
  encoder = spawn(ffmpeg, ['-hide_banner', '-loglevel', 'error', '-y', '-f', 'image2pipe', '-c:v', 'mjpeg',
    '-framerate', String(fps), '-i', '-', ...codec, '-r', String(fps), '-movflags', '+faststart', '-f', 'mp4', opts.out],
  { stdio: ['pipe', 'inherit', 'inherit'] });
  encoderDone = new Promise((res) => encoder.on('close', res));
  const tty = process.stderr.isTTY;
  for (let k = 0; k < frames; ++k) {
    const t = Math.min(t1, t0 + (k * speed) / fps);
    await page.evaluate((time) => window.pdViewer.setTime(time), t);
    const jpeg = await page.screenshot({ type: 'jpeg', quality: 92 });
    if (!encoder.stdin.write(jpeg)) await new Promise((res) => encoder.stdin.once('drain', res));
    if (tty && (k % 10 === 0 || k === frames - 1)) process.stderr.write(`\rmovie: frame ${k + 1} / ${frames}`);
  }
  if (tty) process.stderr.write('\r\x1b[K');
  encoder.stdin.end();
  const code = await encoderDone;
  if (code !== 0) await abandon(1, `ffmpeg exited with ${code}`);
  if (errors.length) await abandon(1, `the page reported: ${errors.join('; ')}`);
  console.error(`movie: ${frames} frames at ${fps} fps (${(frames / fps).toFixed(3)} s), speed ${speed}×`);
} catch (e) {
  await abandon(1, e.message);
}
await browser.close();
