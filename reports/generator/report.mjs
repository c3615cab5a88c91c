#!/usr/bin/env node
// polydyn report DIR [-o FILE] [--viewer FILE | --no-viewer]
//
// Reads what `polydyn gedanken`, `polydyn sweep`, `polydyn compare` and `polydyn cubetoss` wrote into DIR
// (any subset: results.csv, experiments.json, series/*.csv, runs/*/*/summary.json, sweep.csv, metrics.csv,
// cubetoss/ — or DIR itself being a cubetoss directory) and
// writes one self-contained HTML page (Apache ECharts and the page script inlined: no network at view
// time), the numbers it shows as JSON beside it, its derived tables as CSV, and with a viewer bundle
// each replay's data as a script of its own, which the page loads when the replay is opened:
//   FILE (default DIR/report.html), FILE without .html + .json, FILE without .html + -TABLE.csv,
//   FILE without .html + -replays/RUN-HASH.js.
// Each file is written under a temporary name and renamed when complete.
// Exit status: 0 written; 1 failure (e.g. the charting library is not installed); 2 bad input
// (`polydyn report: FILE:LINE: message` on stderr, nothing written); 130 interrupted.
import crypto from 'node:crypto';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { InputError, UsageError, SetupError, WriteError } from './lib/errors.mjs';
import { readResults, readExperiments, readSeries, readSweep, readPrecision, readMetrics, readSummary, readCubetoss, readCompareDetail,
  listCompareScenes } from './lib/inputs.mjs';
import { precision as derivePrecision } from './lib/precision.mjs';
import { loadTypical } from './lib/cubetoss.mjs';
import { compactTrajectory, compactContacts } from './lib/replay.mjs';
import * as derive from './lib/derive.mjs';
import { esc, colorOf } from './lib/html.mjs';
import { writeCsv } from './lib/csv.mjs';
import { sections } from './sections/index.mjs';

const HERE = path.dirname(fileURLToPath(import.meta.url));
const REPO = path.resolve(HERE, '..', '..');
export const DEFAULT_VIEWER = path.join(REPO, 'viewer', 'dist', 'viewer.js');
const REPLAY_MAX_BYTES = 8 << 20;  // a run whose files are larger gets no replay

const GROUP_NAMES = { A: 'contact-model calibration', B: 'friction', C: 'impacts', D: 'rolling, pivoting, polyhedral wheels',
  E: 'paradoxes and indeterminacy', F: 'gyroscopic', G: 'multi-body' };

const USAGE = `usage: polydyn report DIR [-o FILE] [--viewer FILE | --no-viewer]

Writes one self-contained HTML report of DIR (what polydyn gedanken, sweep, compare and cubetoss wrote there),
plus the numbers it shows as JSON and CSV beside it. Sections appear when their inputs exist:
  results.csv, experiments.json   verdict, PASS/FAIL matrix, restitution, friction cone, experiments
  series/EXPERIMENT.csv           each experiment's quantity over time against the analytic line
  runs/*/*/summary.json           the parameters every engine actually used
  sweep.csv                       work-precision diagrams and the cost to reach error 1e-3
  precision.csv                   work-precision of each experiment against its closed form, the cost to
                                  reach its tolerance, and the summary's fronts (gedanken --precision)
  metrics.csv                     comparison metrics
  divergence.csv, impacts.csv,    where, when and why the engines differ (polydyn compare SCENE): a sentence
  series.csv, friction.csv        per engine, the first divergence linked into the replay, each body over
                                  time, the impacts matched across engines, the friction cone
  NAME/divergence.csv             polydyn compare SCENE_DIR: a row per scene, and NAME/report.html for each
  cubetoss/summary.csv            cube tosses against reality (per_toss.csv, fit.csv, replay/TOSS/ or
                                  runs/TOSS/ beside it); DIR may also be a polydyn cubetoss directory
  planar-drops/summary.csv        planar drops against reality (the same files)

  -o FILE         the page (default DIR/report.html); FILE.json (without .html) and FILE-TABLE.csv
                  are written beside it
  --viewer FILE   inline this replay bundle (one copy) and add a 3-D replay of each run
                  (default: viewer/dist/viewer.js of the source tree, when it exists); each replay's
                  data is a file of FILE-replays/ (FILE without .html), loaded when its block is
                  opened: keep that folder beside the page
  --no-viewer     no replays

Exit status: 0 written, 1 failure, 2 bad input (FILE:LINE: message), 130 interrupted.
`;

export function parseArgs(argv) {
  const opts = { dir: null, out: null, viewer: undefined };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    if (a === '-h' || a === '--help') return { help: true };
    if (a === '-o' || a === '--out' || a === '--viewer') {
      if (i + 1 >= argv.length) throw new UsageError(`${a} needs a value`);
      if (a === '--viewer') opts.viewer = argv[++i];
      else opts.out = argv[++i];
    } else if (a === '--no-viewer') opts.viewer = null;
    else if (a.startsWith('-') && a !== '-') throw new UsageError(`unknown option '${a}'`);
    else if (opts.dir === null) opts.dir = a;
    else throw new UsageError(`one directory expected, got '${opts.dir}' and '${a}'`);
  }
  if (opts.dir === null) throw new UsageError('DIR is missing');
  return opts;
}

// Reads and checks every input of DIR (all errors come before anything is written).
export function loadInputs(dir) {
  let st;
  try { st = fs.statSync(dir); } catch { throw new InputError(dir, 0, 'no such directory'); }
  if (!st.isDirectory()) throw new InputError(dir, 0, 'not a directory');
  const inputs = {
    results: readResults(dir),
    experiments: readExperiments(dir),
    series: readSeries(dir),
    sweep: readSweep(dir),
    precision: readPrecision(dir),
    metrics: readMetrics(dir),
    cubetoss: readCubetoss(dir),
    planarDrops: readCubetoss(dir, 'planar-drops'),
  };
  if (!inputs.results && !inputs.experiments && !inputs.series && !inputs.sweep && !inputs.precision && !inputs.metrics && !inputs.cubetoss &&
    !inputs.planarDrops)
    throw new InputError(dir, 0, 'nothing to report: none of results.csv, experiments.json, series/*.csv, sweep.csv, precision.csv, metrics.csv, ' +
      'cubetoss/summary.csv is there');
  inputs.cubetossTypical = inputs.cubetoss ? loadTypical(dir, inputs.cubetoss) : null;
  inputs.planarDropsTypical = inputs.planarDrops ? loadTypical(dir, inputs.planarDrops) : null;
  // polydyn compare SCENE: the runs' details; polydyn compare SCENE_DIR: each scene's, for the overview
  inputs.compareDetail = inputs.metrics ? readCompareDetail(dir) : null;
  inputs.compareRuns = [];
  inputs.compareSummary = null;
  if (inputs.compareDetail && inputs.compareDetail.compare && Array.isArray(inputs.compareDetail.compare.runs)) {
    for (const r of inputs.compareDetail.compare.runs)
      if (r.status === 'ok' && typeof r.run_dir === 'string' && !r.run_dir.includes('..'))
        inputs.compareRuns.push({ ev: `${r.engine} ${r.variant}`, run_dir: r.run_dir });
    const ref = inputs.compareRuns.find((r) => r.ev === 'soft reference');
    const s = ref ? readSummary(dir, ref.run_dir) : null;
    inputs.compareSummary = s ? s.summary : null;
  }
  inputs.compareScenes = inputs.metrics ? listCompareScenes(dir).map((name) => ({ name, detail: readCompareDetail(path.join(dir, name)),
    metrics: readMetrics(path.join(dir, name)) })) : [];
  // run directories named in results.csv, each once
  inputs.runs = [];
  if (inputs.results) {
    const seen = new Set();
    for (const r of inputs.results.rows) {
      if (!r.run_dir || seen.has(r.run_dir)) continue;
      seen.add(r.run_dir);
      const s = readSummary(dir, r.run_dir);
      inputs.runs.push({ ev: r.ev, run_dir: r.run_dir, label: r.experiment + (r.input ? ' ' + r.input : ''), summary: s ? s.summary : null,
        file: s ? s.file : null });
    }
  }
  return inputs;
}

// Replaces non-finite numbers (JSON has none) by "nan", "inf", "-inf".
function finiteReplacer(_key, v) {
  if (typeof v === 'number' && !Number.isFinite(v)) return Number.isNaN(v) ? 'nan' : v > 0 ? 'inf' : '-inf';
  return v;
}

// JSON safe inside <script>: no "<" (so no "</script>" or "<!--").
function scriptJson(v) {
  return JSON.stringify(v, finiteReplacer).replace(/</g, '\\u003c').replace(/\u2028/g, '\\u2028').replace(/\u2029/g, '\\u2029');
}

// A script's source safe inside <script>…</script>.
function scriptSource(text) {
  return text.replace(/<\/(script)/gi, '<\\/$1').replace(/<!--/g, '<\\!--');
}

function readEcharts() {
  const file = path.join(HERE, 'node_modules', 'echarts', 'dist', 'echarts.min.js');
  try {
    return fs.readFileSync(file, 'utf8');
  } catch {
    throw new SetupError(`the charting library is not installed (${file} is missing): run 'npm ci --prefix reports/generator' ` +
      '(scripts/setup does)');
  }
}

function slug(name) {
  return name.replace(/[^A-Za-z0-9_-]+/g, '-');
}

// Builds the page, report.json and the CSV tables in memory.
// replayFolder: the name of the folder beside the page that holds each replay's data (FILE-replays).
export function generate(dir, inputs, { viewerSource = null, echartsSource = readEcharts(), replayFolder = 'report-replays' } = {}) {
  const charts = [];
  const replays = new Map();  // file name in replayFolder → its text
  const lazy = (f) => { let done = false, v; return () => (done ? v : (done = true, v = f())); };
  const results = inputs.results;
  const matrix = lazy(() => (results && results.rows.length ? derive.matrix(results, inputs.experiments) : null));
  const wp = lazy(() => (inputs.sweep && inputs.sweep.rows.length ? derive.workPrecision(inputs.sweep) : null));
  const prec = lazy(() => (inputs.precision && inputs.precision.rows.length ? derivePrecision(inputs.precision, inputs.experiments) : null));
  const evOrder = derive.orderEngineVariants([...(results ? results.rows : []), ...(inputs.sweep ? inputs.sweep.rows : []),
    ...(inputs.precision ? inputs.precision.rows : []),
    ...(inputs.metrics ? inputs.metrics.rows : []), ...(inputs.cubetoss ? inputs.cubetoss.summary : []),
    ...(inputs.planarDrops ? inputs.planarDrops.summary : [])]).map((x) => x.ev);
  const ctx = {
    dir,
    results,
    experiments: inputs.experiments,
    series: inputs.series,
    sweep: inputs.sweep,
    metrics: inputs.metrics,
    cubetoss: inputs.cubetoss,
    cubetossTypical: inputs.cubetossTypical,
    planarDrops: inputs.planarDrops,
    planarDropsTypical: inputs.planarDropsTypical,
    compareDetail: inputs.compareDetail,
    compareRuns: inputs.compareRuns,
    compareSummary: inputs.compareSummary,
    compareScenes: inputs.compareScenes,
    runs: inputs.runs,
    viewer: viewerSource,
    evOrder,
    groupNames: GROUP_NAMES,
    slug,
    experimentList: derive.orderExperiments(results, inputs.experiments),
    get matrix() { return matrix(); },
    get verdicts() { return matrix() ? derive.verdicts(matrix()) : null; },
    get restitution() { return results ? derive.restitution(results) : null; },
    get frictionCone() { return results ? derive.frictionCone(results) : null; },
    get workPrecision() { return wp(); },
    get precision() { return prec(); },
    get cost() { return matrix() || wp() ? derive.cost(matrix(), wp()) : null; },
    color: (ev) => colorOf(ev, evOrder),
    // alternatives: options the page switches between (a select of class pd-alt naming the chart), option the first
    chart(option, { height = 320, width = null, alternatives = null } = {}) {
      const id = `chart-${charts.length + 1}`;
      charts.push(alternatives ? { id, option: null, alternatives } : { id, option });
      return `<div class="chart" id="${id}" style="height:${height}px${width ? `;max-width:${width}px` : ''}"></div>`;
    },
    runData(runDir) {
      const base = path.join(dir, runDir);
      const read = (n) => { try { return fs.readFileSync(path.join(base, n), 'utf8'); } catch { return null; } };
      const trajectory = read('trajectory.csv');
      if (trajectory === null) return null;
      const contacts = read('contacts.csv');
      const summary = read('summary.json');
      if (trajectory.length + (contacts || '').length + (summary || '').length > REPLAY_MAX_BYTES) return null;
      return { run: runDir, summary: summary === null ? null : JSON.parse(summary), trajectory: compactTrajectory(trajectory),
        contacts: compactContacts(contacts) };
    },
    // A closed replay block whose data (what PolydynViewer.mount takes) is written to its own file
    // in replayFolder, a script the page loads when the block is first opened. The file's name ends
    // in a hash of its data, so that a folder written with another page is never taken for this one's.
    replay(runDir, summaryHtml, files) {
      const data = scriptJson(files);
      const hash = crypto.createHash('sha256').update(data).digest('hex').slice(0, 12);
      const name = `${slug(runDir)}-${hash}.js`;
      replays.set(name, `polydynReplay(${JSON.stringify(name)}, ${data});\n`);
      return `<details class="replay" data-run="${esc(runDir)}" data-replay="${esc(name)}"><summary>${summaryHtml}</summary>` +
        '<div class="pd-replay"></div></details>';
    },
  };

  const built = [];
  for (const s of sections) {
    const out = s.build(ctx);
    if (out) built.push({ section: s, ...out });
  }
  if (!built.length) throw new InputError(dir, 0, 'nothing to report: the inputs there give no section (results.csv, series/*.csv, sweep.csv, metrics.csv or cubetoss/summary.csv with rows)');
  const json = {
    format: 'polydyn-report/1',
    directory: dir,
    inputs: inputList(inputs),
    target_error: derive.TARGET_ERROR,
    sections: built.map((b) => b.section.id),
    results: results ? results.rows.map(({ ev, ...r }) => r) : [],
  };
  for (const b of built) json[b.section.id] = b.data;

  const csvs = [];
  for (const b of built) for (const c of b.csv || []) csvs.push({ name: c.name, text: writeCsv(c.header, c.rows) });

  const nav = built.map((b) => `<a href="#${b.section.id}">${esc(b.section.title)}</a>`).join(' · ');
  const body = built.map((b) => `<section id="${b.section.id}"><h2>${esc(b.section.title)}</h2>\n${b.html}\n</section>`).join('\n');
  const css = fs.readFileSync(path.join(HERE, 'page', 'page.css'), 'utf8');
  const pageJs = fs.readFileSync(path.join(HERE, 'page', 'page.js'), 'utf8');
  const html = `<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="polydyn report">
<title>polydyn report — ${esc(path.basename(path.resolve(dir)))}</title>
<style>
${css}</style>
</head>
<body${replays.size ? ` data-replays="${esc(replayFolder)}"` : ''}>
<header><h1>polydyn report <span class="muted">${esc(path.basename(path.resolve(dir)))}</span></h1>
<p class="muted">From ${esc(shortInputs(inputs))}. The numbers shown are in report.json and report-*.csv beside this page.${replays.size ?
    ` The data of the ${replays.size} 3-D replays is in the folder ${esc(replayFolder)}/ beside it (keep the two together).` : ''}</p></header>
<nav>${nav}</nav>
<main>
${body}
</main>
<script type="application/json" id="pd-charts">${scriptJson(charts)}</script>
<script>/* Apache ECharts (Apache-2.0), inlined */
${scriptSource(echartsSource)}
</script>
${viewerSource !== null ? `<script id="pd-viewer-bundle">/* polydyn viewer, inlined once */\n${scriptSource(viewerSource)}\n</script>\n` : ''}<script>
${scriptSource(pageJs)}</script>
</body>
</html>
`;
  return { html, json: JSON.stringify(json, finiteReplacer, 1) + '\n', csvs, replays: [...replays].sort(([a], [b]) => (a < b ? -1 : 1)) };
}

function inputList(inputs) {
  const list = [];
  if (inputs.results) list.push('results.csv');
  if (inputs.experiments) list.push('experiments.json');
  if (inputs.series) list.push(...[...inputs.series.keys()].map((n) => `series/${n}.csv`));
  if (inputs.runs.some((r) => r.summary)) list.push(`${inputs.runs.filter((r) => r.summary).length} × runs/…/summary.json`);
  if (inputs.sweep) list.push('sweep.csv');
  if (inputs.precision) list.push('precision.csv');
  if (inputs.metrics) list.push('metrics.csv');
  if (inputs.cubetoss) list.push(`${inputs.cubetoss.at === '.' ? '' : inputs.cubetoss.at + '/'}summary.csv`);
  if (inputs.planarDrops) list.push('planar-drops/summary.csv');
  return list;
}

// The inputs in a few words, for the page's header.
function shortInputs(inputs) {
  const list = [];
  if (inputs.results) list.push(`results.csv (${inputs.results.rows.length} rows)`);
  if (inputs.experiments) list.push('experiments.json');
  if (inputs.series) list.push(`${inputs.series.size} series`);
  const summaries = inputs.runs.filter((r) => r.summary).length;
  if (summaries) list.push(`${summaries} run summaries`);
  if (inputs.sweep) list.push(`sweep.csv (${inputs.sweep.rows.length} points)`);
  if (inputs.precision) list.push(`precision.csv (${inputs.precision.rows.length} points)`);
  if (inputs.metrics) list.push('metrics.csv');
  if (inputs.cubetoss) list.push(`cube-toss results (${new Set(inputs.cubetoss.summary.map((r) => r.ev)).size} engines)`);
  if (inputs.planarDrops) list.push(`planar-drop results (${new Set(inputs.planarDrops.summary.map((r) => r.ev)).size} engines)`);
  return list.join(', ');
}

// Output paths: the page, its JSON, CSVs and replay folder beside it.
export function outputPaths(dir, out, csvNames = []) {
  const page = out || path.join(dir, 'report.html');
  const stem = page.endsWith('.html') ? page.slice(0, -5) : page;
  return { page, json: stem + '.json', csv: Object.fromEntries(csvNames.map((n) => [n, `${stem}-${n}.csv`])), replays: stem + '-replays' };
}

const temporaries = new Set();
let written = false;  // every output renamed into place
const removeTree = (p) => fs.rmSync(p, { recursive: true, force: true });

// Writes every file under a temporary name, and the replay folder (replays: [name, text] pairs, or
// null for none) as a temporary folder, then renames them all, the page last. The folder replaces the
// one there; a page without replays removes it, so that the page and its folder always belong together.
function writeAll(files, folder, replays) {
  const pending = [];
  const tmp = (p) => { const t = `${p}.tmp-${process.pid}`; temporaries.add(t); return t; };
  try {
    if (replays) {
      const t = tmp(folder);
      removeTree(t);
      fs.mkdirSync(t);
      for (const [name, text] of replays) fs.writeFileSync(path.join(t, name), text);
      pending.push([t, folder]);
    }
    for (const [file, text] of files) {
      const t = tmp(file);
      fs.writeFileSync(t, text);
      pending.push([t, file]);
    }
    const old = `${folder}.old-${process.pid}`;
    temporaries.add(old);
    if (fs.existsSync(folder)) fs.renameSync(folder, old);
    for (const [t, file] of pending) {
      fs.renameSync(t, file);
      temporaries.delete(t);
    }
  } catch (e) {
    if (e && e.code && e.syscall) throw new WriteError(`cannot write ${e.path || path.dirname(folder)}: ${e.code} (${e.syscall})`);
    throw e;
  } finally {
    for (const t of temporaries) removeTree(t);
    temporaries.clear();
  }
}

export function main(argv) {
  const opts = parseArgs(argv);
  if (opts.help) {
    process.stdout.write(USAGE);
    return 0;
  }
  const dir = opts.dir;
  const inputs = loadInputs(dir);
  if (opts.out) {
    const parent = path.dirname(opts.out);
    if (!fs.existsSync(parent) || !fs.statSync(parent).isDirectory()) throw new InputError(opts.out, 0, `directory ${parent} does not exist`);
  }
  let viewerSource = null;
  const viewerPath = opts.viewer === undefined ? (fs.existsSync(DEFAULT_VIEWER) ? DEFAULT_VIEWER : null) : opts.viewer;
  if (viewerPath) {
    try { viewerSource = fs.readFileSync(viewerPath, 'utf8'); } catch (e) { throw new InputError(viewerPath, 0, `cannot read the viewer bundle: ${e.code || e.message}`); }
  }
  // the page of DIR, and with a directory of compared scenes the page of each (DIR/NAME/report.html): all built
  // before any is written
  const pages = [{ dir, out: opts.out, inputs }];
  for (const { name } of inputs.compareScenes) {
    const sub = path.join(dir, name);
    pages.push({ dir: sub, out: null, inputs: loadInputs(sub) });
  }
  const built = pages.map((p) => {
    const replayFolder = outputPaths(p.dir, p.out).replays;
    const g = generate(p.dir, p.inputs, { viewerSource, replayFolder: path.basename(replayFolder) });
    return { ...g, out: outputPaths(p.dir, p.out, g.csvs.map((c) => c.name)) };
  });
  for (const b of built.slice(1).concat(built.slice(0, 1)))
    writeAll([[b.out.json, b.json], ...b.csvs.map((c) => [b.out.csv[c.name], c.text]), [b.out.page, b.html]], b.out.replays,
      b.replays.length ? b.replays : null);
  const { html, csvs, replays, out } = built[0];
  written = true;
  const mb = (n) => `${(n / 1e6).toFixed(1)} MB`;
  process.stderr.write(`polydyn report: wrote ${out.page} (${mb(html.length)}), ${path.basename(out.json)}, ${csvs.length} CSV table${csvs.length === 1 ? '' : 's'}` +
    `${replays.length ? ` and ${replays.length} replays in ${path.basename(out.replays)}/ (${mb(replays.reduce((n, [, t]) => n + t.length, 0))})` : ''}` +
    `${built.length > 1 ? `, and the page of each of the ${built.length - 1} scenes (NAME/report.html)` : ''}\n`);
  return 0;
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  // A signal is handled between synchronous work: after writeAll it finds the report complete (exit 0), before
  // it nothing written but temporaries, which it removes (exit 130).
  for (const sig of ['SIGINT', 'SIGTERM']) {
    process.on(sig, () => {
      for (const tmp of temporaries) removeTree(tmp);
      process.exit(written ? 0 : 130);
    });
  }
  let status;
  try {
    status = main(process.argv.slice(2));
  } catch (e) {
    if (e instanceof InputError) {
      process.stderr.write(`polydyn report: ${e.message}\n`);
      status = 2;
    } else if (e instanceof UsageError) {
      process.stderr.write(`polydyn report: ${e.message} (see 'polydyn report --help')\n`);
      status = 2;
    } else if (e instanceof SetupError || e instanceof WriteError) {
      process.stderr.write(`polydyn report: ${e.message}\n`);
      status = 1;
    } else {
      process.stderr.write(`polydyn report: internal error: ${e && e.stack ? e.stack : e}\n`);
      status = 1;
    }
  }
  process.exitCode = status;
}
