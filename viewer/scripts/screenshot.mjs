// Screenshot of a page written by polydyn view, in headless Chromium.
// usage: node viewer/scripts/screenshot.mjs PAGE.html OUT.png [--time T] [--body NAME] [--size WxH]
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { launch } from './browser.mjs';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 ? args.splice(i, 2)[1] : fallback;
};
const time = option('--time', null);
const body = option('--body', null);
const [width, height] = option('--size', '1280x800').split('x').map(Number);
if (args.length !== 2) {
  console.error('usage: screenshot.mjs PAGE.html OUT.png [--time T] [--body NAME] [--size WxH]');
  process.exit(2);
}
const browser = await launch();
try {
  const page = await browser.context.newPage();
  await page.setViewportSize({ width, height });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(pathToFileURL(resolve(args[0])).href);
  await page.evaluate(() => window.pdViewer.ready);
  await page.evaluate(([t, name]) => {
    const v = window.pdViewer.main;
    if (name) v.selectBody(v.runs[0].bodies.findIndex((b) => b.name === name));
    if (t !== null) window.pdViewer.setTime(+t);
    v.renderNow();
  }, [time, body]);
  await page.screenshot({ path: args[1] });
  if (errors.length) {
    console.error(errors.join('\n'));
    process.exitCode = 1;
  }
} finally {
  await browser.close();
}
