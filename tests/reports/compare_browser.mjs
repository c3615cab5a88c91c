// Browser test of a compared scene's report (polydyn compare SCENE; polydyn report with the real viewer
// bundle), in Debian's Chromium through playwright-core: the page loads from file:// with no network request
// and no console error; its first screen holds one sentence per engine and the first-divergence table; every
// chart draws (an SVG with marks); choosing another body in the body select redraws the per-body charts
// with that body's data; a first-divergence link opens the 3-D replay of every run at that time with that
// body selected, and the replay's view is drawn (pixels other than the clear colour).
// usage: node compare_browser.mjs REPORT.html [--screenshot PNG] [--full PNG]
//   --screenshot: the first screen (1360 × 900); --full: the whole page with the replay open at the link
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

// Debian's Chromium with software WebGL, and the replay view's pixel statistics: the viewer's browser helpers
const HERE = path.dirname(fileURLToPath(import.meta.url));
const { launch, haveChromium, chromiumPath, viewStats } = await import(path.join(HERE, '..', '..', 'viewer', 'scripts', 'browser.mjs'));

const args = process.argv.slice(2);
const opt = (name) => { const k = args.indexOf(name); return k >= 0 ? args[k + 1] : null; };
const file = args[0];
if (!haveChromium()) {
  console.log(`SKIP: no Chromium at ${chromiumPath}`);
  process.exit(77);
}

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok' : 'FAIL'} - ${what}`);
  if (!ok) failures++;
}

const browser = await launch();
try {
  const page = await browser.context.newPage();
  await page.setViewportSize({ width: 1360, height: 900 });
  const problems = [], requests = [];
  page.on('console', (m) => {
    // software WebGL's performance notes are not errors of the page
    if ((m.type() === 'error' || m.type() === 'warning') && !/GL Driver Message|GPU stall|swiftshader/i.test(m.text()))
      problems.push(`console ${m.type()}: ${m.text()}`);
  });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('request', (r) => { if (!/^(file|data|about|blob):/.test(r.url())) requests.push(r.url()); });
  await page.goto(pathToFileURL(path.resolve(file)).href, { waitUntil: 'load' });

  // the first screen answers: a sentence per engine and the first-divergence table, above the fold
  const first = await page.evaluate(() => {
    const items = Array.from(document.querySelectorAll('#differ ul.verdict li'));
    const table = document.querySelector('#differ table.divergence');
    return { sentences: items.map((li) => li.textContent), inView: items.every((li) => li.getBoundingClientRect().bottom <= window.innerHeight),
      tableTop: table ? table.getBoundingClientRect().top : Infinity, rows: table ? table.querySelectorAll('tbody tr').length : 0 };
  });
  const engines = first.sentences.filter((s) => !s.startsWith('Chaos'));
  check(first.sentences.some((s) => s.startsWith('Chaos:')) && engines.length >= 2,
    `one sentence on chaos and one per engine (${engines.length})`);
  check(engines.every((s) => /leaves the reference at [0-9.e-]+ s on |stays within /.test(s)), 'each engine’s sentence says when it leaves the reference, and on which body, or that it never does');
  check(first.inView && first.tableTop < 900, 'the sentences and the first-divergence table are on the first screen');
  if (opt('--screenshot')) await page.screenshot({ path: opt('--screenshot') });

  // every chart draws once scrolled to
  for (const id of await page.evaluate(() => Array.from(document.querySelectorAll('.chart')).map((el) => el.id))) {
    await page.locator(`#${id}`).scrollIntoViewIfNeeded();
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  }
  const charts = await page.evaluate(() => Array.from(document.querySelectorAll('.chart')).map((el) => {
    const svg = el.querySelector('svg');
    return { id: el.id, marks: svg ? svg.querySelectorAll('path, text').length : 0 };
  }));
  check(charts.length >= 6 && charts.every((c) => c.marks >= 10), `every chart drew (${charts.length}; blank: ${charts.filter((c) => c.marks < 10).map((c) => c.id).join(', ') || 'none'})`);

  // the body select switches the per-body charts to that body's data
  const switched = await page.evaluate(() => {
    const select = document.querySelector('select.pd-alt');
    if (!select) return null;
    if (select.options.length < 2) return { single: true };
    const id = select.dataset.charts.split(' ')[0];
    const chart = window.polydynReport.specs.find((s) => s.id === id).chart;
    const data = () => JSON.stringify(chart.getOption().series.map((s) => s.data));
    const before = data();
    select.value = '1';
    select.dispatchEvent(new Event('change'));
    const after = data();
    const spec = window.polydynReport.specs.find((s) => s.id === id);
    return { changed: before !== after, matches: after === JSON.stringify(spec.alternatives[1].series.map((s) => s.data)) };
  });
  if (switched && switched.single) console.log('# one moving body: no other body to choose');
  else check(switched && switched.changed && switched.matches, 'choosing another body redraws the per-body charts with its data');

  // a first-divergence link opens the replay at that time, with that body selected, and the view draws
  const link = await page.evaluate(() => {
    const a = document.querySelector('#differ table.divergence a.pd-seek');
    return a ? { t: Number(a.dataset.t), body: a.dataset.body } : null;
  });
  check(link !== null, 'the first-divergence table links into the replay');
  if (link) {
    await page.click('#differ table.divergence a.pd-seek');
    await page.waitForFunction(() => { const d = document.querySelector('#pd-differ-replay details.replay'); return d && d.pdReplay; },
      null, { timeout: 30000 }).catch(() => {});
    const state = await page.evaluate(() => {
      const d = document.querySelector('#pd-differ-replay details.replay');
      const r = d && d.pdReplay;
      if (!r) return null;
      r.renderNow();
      return { t: r.t, runs: r.runs.length, selected: r.selected >= 0 ? r.runs[0].bodies[r.selected].name : null };
    });
    check(state && Math.abs(state.t - link.t) < 1e-9, `the replay opened at the link's time (${state ? state.t : 'not mounted'} s, link ${link.t} s)`);
    check(state && state.selected === link.body, `with the diverging body selected (${state ? state.selected : '—'})`);
    check(state && state.runs >= 3, `the reference and the engines overlaid (${state ? state.runs : 0} runs)`);
    const canvas = page.locator('#pd-differ-replay canvas').first();
    await canvas.scrollIntoViewIfNeeded();
    const { drawn } = await viewStats(page, canvas);
    check(drawn > 0.02, `the replay's view is drawn (${(100 * drawn).toFixed(1)} % of its pixels)`);
    if (opt('--full')) await page.screenshot({ path: opt('--full'), fullPage: true });
  }
  check(problems.length === 0, `no console errors or warnings${problems.length ? ': ' + problems.join(' | ') : ''}`);
  check(requests.length === 0, `no network request${requests.length ? ': ' + requests.join(', ') : ''}`);
} finally {
  await browser.close();
}
console.log(failures === 0 ? 'all checks passed' : `${failures} check(s) failed`);
process.exitCode = failures ? 1 : 0;
