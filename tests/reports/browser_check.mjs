// Browser smoke test of a generated report, in Debian's Chromium (never a downloaded browser) through
// playwright-core: the page loads from file:// without a single network request or console error,
// the charts far below the first screen wait until scrolled to, then every chart has drawn (a non-empty
// SVG with marks), and every replay, once opened, loads its data from the folder beside the page and
// draws it (its canvas has drawn pixels).
// --missing-replays PAGE: a page whose replay folder is gone: every opened replay says that its data is
// missing, and the only console errors are the failed loads of those files.
// usage: node browser_check.mjs REPORT.html... [--missing-replays PAGE] [--screenshot PNG [--until SECTION_ID]] [--width W] [--height H]
//   --screenshot: a full-page screenshot of the first page, or down to the end of section SECTION_ID
//   (reports/report-fixture.png is `--screenshot reports/report-fixture.png --until cost`)
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath, pathToFileURL } from 'node:url';

const HERE = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(HERE, '..', '..', 'reports', 'generator', 'package.json'));
const { chromium } = require('playwright-core');

const args = process.argv.slice(2);
const opt = (name, dflt) => { const k = args.indexOf(name); return k >= 0 ? args[k + 1] : dflt; };
const pages = args.filter((a, k) => !a.startsWith('--') && !(k > 0 && args[k - 1].startsWith('--')));
const shot = opt('--screenshot', null);
const missingReplays = opt('--missing-replays', null);
const CHROMIUM = process.env.PD_CHROMIUM || '/usr/bin/chromium';

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok' : 'FAIL'} - ${what}`);
  if (!ok) failures++;
}

const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'pd-report-chromium-'));
const context = await chromium.launchPersistentContext(userDataDir, {
  executablePath: CHROMIUM,
  headless: true,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync'],
  viewport: { width: Number(opt('--width', 1360)), height: Number(opt('--height', 900)) },
});
try {
  for (const [k, file] of [...pages, ...(missingReplays ? [missingReplays] : [])].entries()) {
    const dataGone = file === missingReplays && k === pages.length;
    console.log(`# ${file}${dataGone ? ' (its replay folder removed)' : ''}`);
    const page = await context.newPage();
    const problems = [];
    const requests = [];
    const failedLoads = [];
    page.on('console', (m) => {
      if (dataGone && m.type() === 'error' && /^Failed to load resource: net::ERR_FILE_NOT_FOUND/.test(m.text())) failedLoads.push(m.location().url);
      else if (m.type() === 'error' || m.type() === 'warning') problems.push(`console ${m.type()}: ${m.text()}`);
    });
    page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
    page.on('request', (r) => { if (!/^(file|data|about|blob):/.test(r.url())) requests.push(r.url()); });
    await page.goto(pathToFileURL(path.resolve(file)).href, { waitUntil: 'load' });
    await page.waitForTimeout(300);

    // charts are drawn as they come near the screen: those far below wait; scrolled to, each draws
    const waiting = await page.evaluate(() => Array.from(document.querySelectorAll('.chart'))
      .filter((el) => el.getBoundingClientRect().top > window.innerHeight + 1600).map((el) => !!el.querySelector('svg')));
    if (waiting.length) check(waiting.every((drawn) => !drawn), `the ${waiting.length} charts far below the first screen are not drawn at load`);
    for (const id of await page.evaluate(() => Array.from(document.querySelectorAll('.chart')).map((el) => el.id))) {
      await page.locator(`#${id}`).scrollIntoViewIfNeeded();
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    }
    await page.evaluate(() => window.scrollTo(0, 0));
    const charts = await page.evaluate(() => Array.from(document.querySelectorAll('.chart')).map((el) => {
      const svg = el.querySelector('svg');
      const r = el.getBoundingClientRect();
      return { id: el.id, width: r.width, height: r.height, svg: !!svg, marks: svg ? svg.querySelectorAll('path, circle, polyline, text').length : 0 };
    }));
    check(charts.length > 0, `the page has charts (${charts.length})`);
    const blank = charts.filter((c) => !c.svg || c.marks < 10 || c.width < 100 || c.height < 100);
    check(blank.length === 0, `every chart drew an SVG with marks${blank.length ? ': blank ' + blank.map((c) => c.id).join(', ') : ''}`);
    const kinds = await page.evaluate(() => {
      const cs = window.polydynReport ? window.polydynReport.charts : [];
      return { polar: cs.filter((c) => (c.getOption().polar || []).length).length,
        loglog: cs.filter((c) => (c.getOption().xAxis || []).some((a) => a.type === 'log')).length };
    });
    console.log(`# ${charts.length} charts, ${kinds.polar} polar, ${kinds.loglog} log-log`);
    const replays = await page.evaluate(() => {
      const ds = Array.from(document.querySelectorAll('details.replay'));
      ds.forEach((d) => { d.open = true; });
      return ds.length;
    });
    if (replays && !dataGone) {
      // each replay's data is a script loaded on opening: wait until every replay has mounted (or 10 s)
      await page.waitForFunction((n) => document.querySelectorAll('details.replay .pd-replay [data-mounted-run]').length === n,
        replays, { timeout: 10000 }).catch(() => {});
      const drawn = await page.evaluate(() => Array.from(document.querySelectorAll('details.replay')).map((d) => {
        const c = d.querySelector('.pd-replay [data-mounted-run]');
        if (!c) return { run: d.dataset.run, mounted: null, pixels: 0 };
        const px = c.getContext ? c.getContext('2d').getImageData(0, 0, c.width, c.height).data : [];
        let pixels = 0;
        for (let i = 3; i < px.length; i += 4) if (px[i] > 0) pixels++;
        return { run: d.dataset.run, mounted: c.dataset.mountedRun.split(' + ')[0], pixels };
      }));
      const mounted = drawn.filter((r) => r.mounted === r.run);
      check(mounted.length === replays, `every replay loads its own run's data when opened (${mounted.length} of ${replays})`);
      const blank = drawn.filter((r) => r.pixels < 50);
      check(blank.length === 0, `every replay draws its trajectory${blank.length ? ': blank ' + blank.map((r) => r.run).join(', ') : ''}`);
    }
    if (replays && dataGone) {
      await page.waitForFunction((n) => document.querySelectorAll('details.replay .pd-replay.pd-missing').length === n,
        replays, { timeout: 10000 }).catch(() => {});
      const said = await page.evaluate(() => Array.from(document.querySelectorAll('details.replay .pd-replay'))
        .filter((t) => /^The replay data is missing: this page loads it from .+-replays\//.test(t.textContent) && !t.querySelector('canvas')).length);
      check(said === replays, `every replay says that its data is missing (${said} of ${replays})`);
      check(failedLoads.length === replays && failedLoads.every((u) => /-replays\/[^/]+\.js$/.test(u)),
        `the only failed loads are the ${replays} replay files (${failedLoads.length})`);
    }
    if (dataGone) check(replays > 0, `the page with its replay folder removed has replays (${replays})`);
    check(problems.length === 0, `no console errors or warnings${problems.length ? ': ' + problems.join(' | ') : ''}`);
    check(requests.length === 0, `no network request${requests.length ? ': ' + requests.join(', ') : ''}`);
    if (shot && k === 0) {
      await page.evaluate(() => document.querySelectorAll('details.replay').forEach((d) => { d.open = false; }));
      const until = opt('--until', null);
      const bottom = until ? await page.evaluate((id) => {
        const el = document.getElementById(id);
        return el ? Math.ceil(el.getBoundingClientRect().bottom + window.scrollY) + 16 : null;
      }, until) : null;
      if (until && bottom === null) check(false, `section ${until} for the screenshot`);
      await page.screenshot({ path: shot, fullPage: true, ...(bottom ? { clip: { x: 0, y: 0, width: page.viewportSize().width, height: bottom } } : {}) });
    }
    await page.close();
  }
} finally {
  await context.close();
  fs.rmSync(userDataDir, { recursive: true, force: true });
}
console.log(`${failures === 0 ? 'all checks passed' : failures + ' check(s) failed'}`);
process.exitCode = failures ? 1 : 0;
