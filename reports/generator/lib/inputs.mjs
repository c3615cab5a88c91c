// The inputs of a report directory, read and checked against the schemas of DESIGN / the gedanken,
// sweep and compare commands. Every reader returns null when its file does not exist (a section then
// does not appear) and throws InputError(FILE, LINE, message) when the file is there but malformed.
import fs from 'node:fs';
import path from 'node:path';
import { parseCsv } from './csv.mjs';
import { parseJson, lineOf } from './json.mjs';
import { InputError } from './errors.mjs';

export const RESULTS_HEADER = ['experiment', 'group', 'title', 'engine', 'variant', 'quantity', 'unit', 'input',
  'measured', 'expected', 'error', 'tolerance', 'status', 'wall_seconds', 'run_dir', 'note'];
export const SERIES_HEADER = ['t', 'engine', 'variant', 'input', 'value', 'analytic'];
// sweep.csv as written since the derivative counts (the last column), before them (the self-convergence
// columns last), and before those: all three are read.
export const SWEEP_HEADER_V1 = ['scene', 'engine', 'variant', 'setting', 'value', 'error', 'error_kind', 'wall_seconds',
  'wall_per_sim_second', 'steps', 'repeats', 'reference'];
export const SWEEP_HEADER_V2 = [...SWEEP_HEADER_V1, 'self_error', 'self_reference', 'horizon_seconds'];
export const SWEEP_HEADER = [...SWEEP_HEADER_V2, 'derivatives'];
// what set the size of polydyn's accepted steps (pdStepLimit, docs/integration.md), one column each
export const STEP_LIMITS = ['error', 'largest', 'stability', 'travel', 'event', 'landing'];
// the timings' median and spread, appended after note (a point's cost is the least of its timings)
export const PRECISION_TIMING_COLUMNS = ['cpu_seconds_median', 'cpu_max_over_min', 'wall_seconds_median', 'wall_max_over_min',
  'runs_per_timing'];
// before the timings' median and spread: wall_seconds and cpu_seconds were the median of the repeats' single runs
const PRECISION_HEADER_MEDIAN = ['experiment', 'kind', 'engine', 'variant', 'setting', 'value', 'input', 'quantity', 'unit',
  'measured', 'expected', 'error', 'relative', 'tolerance', 'judged', 'status', 'wall_seconds', 'wall_per_sim_second', 'steps',
  'repeats', 'cpu_seconds', 'cpu_per_sim_second', 'derivatives', ...STEP_LIMITS.map((l) => `steps_${l}`), 'note'];
export const PRECISION_HEADER = [...PRECISION_HEADER_MEDIAN, ...PRECISION_TIMING_COLUMNS];
// before the derivative evaluations and the steps' limits were counted
const PRECISION_HEADER_CPU = PRECISION_HEADER_MEDIAN.filter((h) => h !== 'derivatives' && !STEP_LIMITS.some((l) => h === `steps_${l}`));
// before the CPU time was measured
const PRECISION_HEADER_WALL_ONLY = PRECISION_HEADER_CPU.filter((h) => !h.startsWith('cpu_'));
export const PRECISION_STATUSES = ['ok', 'failed', 'no_measure', 'refused', 'not_built'];
export const METRICS_HEADER = ['scene', 'engine', 'variant', 'reference', 'pos_err_final', 'pos_err_rms',
  'rot_err_final_rad', 'rot_err_rms_rad', 'energy_drift_rel', 'momentum_drift_rel', 'max_penetration_over_size',
  'wall_per_sim_second', 'steps', 'restitution_impacts'];
export const STATUSES = ['PASS', 'FAIL', 'REFUSED', 'NOT_BUILT', 'ERROR', 'NOT_APPLICABLE'];

const NUMBER = /^[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?$/;
const NONFINITE = { nan: NaN, '-nan': NaN, inf: Infinity, '+inf': Infinity, '-inf': -Infinity, infinity: Infinity,
  '-infinity': -Infinity };
const WORD = /^[A-Za-z0-9_.+-]+$/;

// Reads a file of the report directory; null when it does not exist. `shown` is the path as printed.
export function readText(dir, name) {
  const file = path.join(dir, name);
  let text;
  try {
    text = fs.readFileSync(file);
  } catch (e) {
    if (e.code === 'ENOENT') return null;
    if (e.code === 'EISDIR') throw new InputError(file, 0, 'is a directory, not a file');
    throw new InputError(file, 0, `cannot read: ${e.message}`);
  }
  if (text.includes(0)) throw new InputError(file, 0, 'not a text file (contains NUL bytes)');
  return { file, text: text.toString('utf8') };
}

// A number field: null when empty; nan/inf as C prints them are accepted; anything else is an error.
function number(value, column, file, line, { required = false, positive = false, integer = false } = {}) {
  const v = value.trim();
  if (v === '') {
    if (required) throw new InputError(file, line, `${column}: empty (a number is required)`);
    return null;
  }
  let x;
  if (NUMBER.test(v)) x = Number(v);
  else if (Object.prototype.hasOwnProperty.call(NONFINITE, v.toLowerCase())) x = NONFINITE[v.toLowerCase()];
  else throw new InputError(file, line, `${column}: not a number: '${value}'`);
  if (positive && !(x > 0 && Number.isFinite(x))) throw new InputError(file, line, `${column}: must be a finite number > 0, not '${value}'`);
  if (integer && !(Number.isInteger(x) && x >= 0)) throw new InputError(file, line, `${column}: must be a whole number ≥ 0, not '${value}'`);
  return x;
}

// Records of a CSV file with an exact header; blank lines and repeated header lines (several files
// concatenated) are skipped. `older`: earlier headers also accepted, each part of the file read with the
// header above it (the columns it lacks absent from f). Returns [{line, f: {column: text}}].
function table(src, header, older = []) {
  const records = parseCsv(src.text, src.file);
  if (records.length === 0) throw new InputError(src.file, 1, `empty file (expected the header ${header.join(',')})`);
  const first = records[0];
  const headers = [header, ...older];
  const find = (fields) => headers.findIndex((h) => h.join(',') === fields.join(','));
  if (find(first.fields) < 0)
    throw new InputError(src.file, first.line, `header must be exactly '${header.join(',')}'` +
      `${older.map((h) => ` or '${h.join(',')}'`).join('')}, found '${first.fields.join(',')}'`);
  header = headers[find(first.fields)];
  const out = [];
  for (const r of records.slice(1)) {
    if (r.fields.length === 1 && r.fields[0].trim() === '') continue;
    if (find(r.fields) >= 0) {
      header = headers[find(r.fields)];
      continue;
    }
    if (r.fields.length !== header.length)
      throw new InputError(src.file, r.line, `${header.length} fields expected, ${r.fields.length} found`);
    const f = {};
    header.forEach((h, k) => { f[h] = r.fields[k]; });
    out.push({ line: r.line, f });
  }
  return out;
}

function word(value, column, file, line) {
  if (!WORD.test(value)) throw new InputError(file, line, `${column}: expected a name (letters, digits, _ . + -), found '${value}'`);
  return value;
}

// input `name=value` → {inputName, inputValue (number or null when not numeric)}
function parseInput(value, file, line) {
  if (value === '') return { inputName: '', inputValue: null };
  const m = /^([A-Za-z_][A-Za-z0-9_]*)=(.+)$/.exec(value);
  if (!m) throw new InputError(file, line, `input: expected name=value or empty, found '${value}'`);
  const x = NUMBER.test(m[2]) ? Number(m[2]) : null;
  return { inputName: m[1], inputValue: x };
}

// A run directory named in a CSV: relative, inside DIR.
function runDir(value, file, line) {
  if (value === '') return '';
  const parts = value.split('/');
  if (value.startsWith('/') || parts.includes('..'))
    throw new InputError(file, line, `run_dir: must be a path inside the report directory, found '${value}'`);
  return parts.filter((p) => p !== '' && p !== '.').join('/');
}

export function readResults(dir) {
  const src = readText(dir, 'results.csv');
  if (!src) return null;
  const rows = [];
  const seen = new Map();
  for (const { line, f } of table(src, RESULTS_HEADER)) {
    const file = src.file;
    if (f.experiment === '') throw new InputError(file, line, 'experiment: empty');
    if (!/^[A-Z]$/.test(f.group)) throw new InputError(file, line, `group: expected one capital letter (A..G), found '${f.group}'`);
    if (!STATUSES.includes(f.status))
      throw new InputError(file, line, `status: expected one of ${STATUSES.join(', ')}, found '${f.status}'`);
    const row = {
      line,
      experiment: f.experiment,
      group: f.group,
      title: f.title,
      engine: word(f.engine, 'engine', file, line),
      variant: word(f.variant, 'variant', file, line),
      quantity: f.quantity,
      unit: f.unit,
      input: f.input,
      ...parseInput(f.input, file, line),
      measured: number(f.measured, 'measured', file, line),
      expected: number(f.expected, 'expected', file, line),
      error: number(f.error, 'error', file, line),
      tolerance: number(f.tolerance, 'tolerance', file, line),
      status: f.status,
      wall_seconds: number(f.wall_seconds, 'wall_seconds', file, line),
      run_dir: runDir(f.run_dir, file, line),
      note: f.note,
    };
    row.ev = `${row.engine} ${row.variant}`;
    row.relative = /\brelative\b/i.test(row.note);
    const key = [row.experiment, row.engine, row.variant, row.input].join('\u0000');
    if (seen.has(key))
      throw new InputError(file, line, `duplicate row: same experiment, engine, variant and input as line ${seen.get(key)}`);
    seen.set(key, line);
    rows.push(row);
  }
  return { file: src.file, rows };
}

const EXPERIMENT_FIELDS = { name: 'string', group: 'string', title: 'string', quantity: 'string', unit: 'string',
  formula: 'string', tolerance_reason: 'string', qualitative: 'boolean', scene: 'string', series_label: 'string' };

export function readExperiments(dir) {
  const src = readText(dir, 'experiments.json');
  if (!src) return null;
  const list = parseJson(src.text, src.file);
  if (!Array.isArray(list)) throw new InputError(src.file, lineOf(list) || 1, 'expected an array of experiments');
  const names = new Map();
  for (const e of list) {
    const line = lineOf(e) || lineOf(list);
    if (!e || typeof e !== 'object' || Array.isArray(e)) throw new InputError(src.file, line, 'expected an object for each experiment');
    for (const [k, type] of Object.entries(EXPERIMENT_FIELDS)) {
      if (!(k in e)) throw new InputError(src.file, line, `experiment${typeof e.name === 'string' ? ` "${e.name}"` : ''}: missing "${k}"`);
      if (typeof e[k] !== type) throw new InputError(src.file, line, `"${k}" must be a ${type}`);
    }
    // what the experiment tests (FORMATS): optional, an experiment without a kind is a law
    if ('kind' in e && !['law', 'model_prediction'].includes(e.kind))
      throw new InputError(src.file, line, `"kind" must be "law" or "model_prediction"`);
    if ('applies_to' in e && !(Array.isArray(e.applies_to) && e.applies_to.every((x) => typeof x === 'string')))
      throw new InputError(src.file, line, '"applies_to" must be an array of "ENGINE-VARIANT" strings');
    if (e.kind === 'model_prediction' && typeof e.not_applicable_reason !== 'string')
      throw new InputError(src.file, line, `experiment "${e.name}": a model prediction needs "not_applicable_reason" (a string)`);
    if (names.has(e.name)) throw new InputError(src.file, line, `duplicate experiment "${e.name}" (first at line ${names.get(e.name)})`);
    names.set(e.name, line);
  }
  return { file: src.file, list };
}

// DIR/series/*.csv → Map(experiment → {file, points: [{line, t, engine, variant, input, value, analytic}]})
export function readSeries(dir) {
  let names;
  try {
    names = fs.readdirSync(path.join(dir, 'series')).filter((n) => n.endsWith('.csv')).sort();
  } catch (e) {
    if (e.code === 'ENOENT' || e.code === 'ENOTDIR') return null;
    throw e;
  }
  const out = new Map();
  for (const name of names) {
    const src = readText(dir, path.join('series', name));
    if (!src) continue;
    const points = [];
    for (const { line, f } of table(src, SERIES_HEADER)) {
      points.push({
        t: number(f.t, 't', src.file, line, { required: true }),
        engine: word(f.engine, 'engine', src.file, line),
        variant: word(f.variant, 'variant', src.file, line),
        input: f.input,
        value: number(f.value, 'value', src.file, line),
        analytic: number(f.analytic, 'analytic', src.file, line),
      });
      parseInput(f.input, src.file, line);
    }
    out.set(name.slice(0, -4), { file: src.file, points });
  }
  return out.size ? out : null;
}

export function readSweep(dir) {
  const src = readText(dir, 'sweep.csv');
  if (!src) return null;
  const rows = [];
  for (const { line, f } of table(src, SWEEP_HEADER, [SWEEP_HEADER_V2, SWEEP_HEADER_V1])) {
    if (f.scene === '') throw new InputError(src.file, line, 'scene: empty');
    if (f.setting !== 'tol' && f.setting !== 'step')
      throw new InputError(src.file, line, `setting: expected tol or step, found '${f.setting}'`);
    const row = {
      line,
      scene: f.scene,
      engine: word(f.engine, 'engine', src.file, line),
      variant: word(f.variant, 'variant', src.file, line),
      setting: f.setting,
      value: number(f.value, 'value', src.file, line, { required: true, positive: true }),
      error: number(f.error, 'error', src.file, line),
      error_kind: f.error_kind,
      wall_seconds: number(f.wall_seconds, 'wall_seconds', src.file, line),
      wall_per_sim_second: number(f.wall_per_sim_second, 'wall_per_sim_second', src.file, line),
      steps: number(f.steps, 'steps', src.file, line, { integer: true }),
      repeats: number(f.repeats, 'repeats', src.file, line, { integer: true }),
      reference: f.reference,
      // self-convergence (absent before those columns: has_self false, the three null)
      has_self: 'self_reference' in f,
      self_error: 'self_error' in f ? number(f.self_error, 'self_error', src.file, line) : null,
      self_reference: 'self_reference' in f ? f.self_reference : null,
      horizon_seconds: 'horizon_seconds' in f ? number(f.horizon_seconds, 'horizon_seconds', src.file, line) : null,
      // the soft engine's derivative evaluations (empty for ODE and Bullet; null before that column)
      derivatives: 'derivatives' in f ? number(f.derivatives, 'derivatives', src.file, line, { integer: true }) : null,
    };
    if (row.horizon_seconds !== null && !(row.horizon_seconds >= 0 && Number.isFinite(row.horizon_seconds)))
      throw new InputError(src.file, line, `horizon_seconds: must be empty or a finite number ≥ 0, not '${f.horizon_seconds}'`);
    row.ev = `${row.engine} ${row.variant}`;
    rows.push(row);
  }
  return { file: src.file, rows };
}

function bool(value, column, file, line) {
  if (value !== 'true' && value !== 'false') throw new InputError(file, line, `${column}: expected true or false, found '${value}'`);
  return value === 'true';
}

// precision.csv of `polydyn gedanken --precision` (gedanken/RESULT_SCHEMAS.md): one row per work-precision point.
export function readPrecision(dir) {
  const src = readText(dir, 'precision.csv');
  if (!src) return null;
  const rows = [];
  for (const { line, f } of table(src, PRECISION_HEADER, [PRECISION_HEADER_MEDIAN, PRECISION_HEADER_CPU, PRECISION_HEADER_WALL_ONLY])) {
    if (f.experiment === '') throw new InputError(src.file, line, 'experiment: empty');
    const status = oneOf(f.status, PRECISION_STATUSES, 'status', src.file, line);
    if (status !== 'not_built' && !['tol', 'step', 'iterations'].includes(f.setting))
      throw new InputError(src.file, line, `setting: expected tol, step or iterations, found '${f.setting}'`);
    const row = {
      line,
      experiment: word(f.experiment, 'experiment', src.file, line),
      kind: oneOf(f.kind, ['law', 'model_prediction'], 'kind', src.file, line),
      engine: word(f.engine, 'engine', src.file, line),
      variant: word(f.variant, 'variant', src.file, line),
      setting: f.setting,
      value: number(f.value, 'value', src.file, line, { required: status !== 'not_built', positive: status !== 'not_built' }),
      input: f.input,
      quantity: f.quantity,
      unit: f.unit,
      measured: number(f.measured, 'measured', src.file, line),
      expected: number(f.expected, 'expected', src.file, line, { required: true }),
      error: number(f.error, 'error', src.file, line),
      relative: bool(f.relative, 'relative', src.file, line),
      tolerance: number(f.tolerance, 'tolerance', src.file, line, { required: true, positive: true }),
      judged: bool(f.judged, 'judged', src.file, line),
      status,
      wall_seconds: number(f.wall_seconds, 'wall_seconds', src.file, line),
      wall_per_sim_second: number(f.wall_per_sim_second, 'wall_per_sim_second', src.file, line),
      steps: number(f.steps, 'steps', src.file, line, { integer: true }),
      repeats: number(f.repeats, 'repeats', src.file, line, { integer: true }),
      cpu_seconds: number(f.cpu_seconds ?? '', 'cpu_seconds', src.file, line),
      cpu_per_sim_second: number(f.cpu_per_sim_second ?? '', 'cpu_per_sim_second', src.file, line),
      derivatives: number(f.derivatives ?? '', 'derivatives', src.file, line, { integer: true }),
      // null where not counted (the reference engines, polydyn's fixed step, files from before the counts)
      steps_limited_by: STEP_LIMITS.every((l) => (f[`steps_${l}`] ?? '') !== '')
        ? Object.fromEntries(STEP_LIMITS.map((l) => [l, number(f[`steps_${l}`], `steps_${l}`, src.file, line, { integer: true })]))
        : null,
      note: f.note,
      // the timings' median and spread (null in files from before them, whose costs are medians of single runs)
      cpu_seconds_median: number(f.cpu_seconds_median ?? '', 'cpu_seconds_median', src.file, line),
      cpu_max_over_min: number(f.cpu_max_over_min ?? '', 'cpu_max_over_min', src.file, line),
      wall_seconds_median: number(f.wall_seconds_median ?? '', 'wall_seconds_median', src.file, line),
      wall_max_over_min: number(f.wall_max_over_min ?? '', 'wall_max_over_min', src.file, line),
      runs_per_timing: number(f.runs_per_timing ?? '', 'runs_per_timing', src.file, line, { integer: true }),
    };
    if (status === 'ok' && (row.error === null || row.wall_per_sim_second === null))
      throw new InputError(src.file, line, 'an ok point needs its error and wall_per_sim_second');
    row.ev = `${row.engine} ${row.variant}`;
    rows.push(row);
  }
  return { file: src.file, rows };
}

export function readMetrics(dir) {
  const src = readText(dir, 'metrics.csv');
  if (!src) return null;
  const rows = [];
  for (const { line, f } of table(src, METRICS_HEADER)) {
    const row = { line, scene: f.scene, engine: word(f.engine, 'engine', src.file, line),
      variant: word(f.variant, 'variant', src.file, line), reference: f.reference };
    for (const h of METRICS_HEADER.slice(4, 13)) row[h] = number(f[h], h, src.file, line, { integer: h === 'steps' });
    row.restitution_impacts = f.restitution_impacts;
    row.ev = `${row.engine} ${row.variant}`;
    rows.push(row);
  }
  return { file: src.file, rows };
}

// summary.json of a run directory (relative to DIR): the parsed object, or null when absent.
export function readSummary(dir, run) {
  const src = readText(dir, path.join(run, 'summary.json'));
  if (!src) return null;
  const v = parseJson(src.text, src.file);
  if (!v || typeof v !== 'object' || Array.isArray(v)) throw new InputError(src.file, 1, 'expected a JSON object');
  if ('engine_settings' in v && (!v.engine_settings || typeof v.engine_settings !== 'object' || Array.isArray(v.engine_settings)))
    throw new InputError(src.file, lineOf(v), '"engine_settings" must be an object');
  if ('bodies' in v && !Array.isArray(v.bodies)) throw new InputError(src.file, lineOf(v), '"bodies" must be an array');
  return { file: src.file, summary: v };
}

// ---------------------------------------------------------------- cube tosses (polydyn cubetoss)

export const TOSS_SUMMARY_HEADER = ['engine', 'variant', 'params', 'split', 'status', 'tosses', 'completed', 'quantity', 'unit',
  'mean', 'median', 'p90'];
export const PER_TOSS_HEADER = ['toss', 'split', 'engine', 'variant', 'params', 'status', 'samples', 'duration_s', 'pos_err_end',
  'pos_err_rms', 'rot_err_end_rad', 'rot_err_rms_rad', 'wall_seconds', 'cpu_seconds', 'steps', 'run_dir', 'message'];
// Planar experiments (the planar drops) add their bounces after the pose errors.
export const IMPACT_FIELDS = [1, 2, 3].flatMap((k) => [`impact${k}_dt_s`, `impact${k}_dv`, `impact${k}_dw`]);
export const PER_TOSS_HEADER_PLANAR = [...PER_TOSS_HEADER.slice(0, 12), 'impacts_record', 'impacts_run', ...IMPACT_FIELDS,
  ...PER_TOSS_HEADER.slice(12)];
const FIT_HEADER_POSE = ['engine', 'variant', 'status', 'fitted', 'mu', 'restitution', 'kn', 'objective_train',
  'pos_err_end_mean_train', 'rot_err_end_mean_train_rad', 'failed_train', 'evaluations', 'converged', 'train_tosses',
  'train_every', 'test_tosses', 'start_mu', 'start_restitution', 'start_kn', 'start_objective_train'];
export const FIT_HEADER = [...FIT_HEADER_POSE, 'bounce_dv_mean_train'];
const TOSS_SPLITS = ['all', 'train', 'test'];
const TOSS_SUMMARY_STATUSES = ['ok', 'partial', 'failed', 'not built'];
const TOSS_STATUSES = ['ok', 'failed', 'refused', 'not built'];
const PROVENANCE = /^- (command|commit|machine|data|split|fit): (.+)$/;

function oneOf(value, list, column, file, line) {
  if (!list.includes(value)) throw new InputError(file, line, `${column}: expected one of ${list.join(', ')}, found '${value}'`);
  return value;
}

function exists(file) {
  try { return fs.statSync(file).isFile(); } catch { return false; }
}

// The cube-toss results of a report directory: DIR/cubetoss/ (scripts/gedanken-report copies the
// committed reports/cubetoss/ there), or DIR itself when it is what `polydyn cubetoss --out DIR` wrote
// (per_toss.csv and summary.csv). Reads summary.csv, per_toss.csv, fit.csv and the provenance lines of
// README.md (scripts/cubetoss-all writes them) when present; null when there are no cube-toss results.
// `at` is the directory relative to DIR ('cubetoss' or '.'). With `sub` ('planar-drops') only DIR/sub/ is
// read. `planar`: the results hold bounces (per_toss.csv of the planar drops).
export function readCubetoss(dir, sub = null) {
  let at;
  if (sub) {
    if (!fs.existsSync(path.join(dir, sub))) return null;
    at = sub;
  } else if (fs.existsSync(path.join(dir, 'cubetoss'))) at = 'cubetoss';
  else if (exists(path.join(dir, 'per_toss.csv')) && exists(path.join(dir, 'summary.csv'))) at = '.';
  else return null;
  const where = path.join(dir, at);
  const summarySrc = readText(where, 'summary.csv');
  if (!summarySrc) throw new InputError(path.join(where, 'summary.csv'), 0, 'missing (a cube-toss directory needs the summary.csv of polydyn cubetoss)');
  const summary = [];
  for (const { line, f } of table(summarySrc, TOSS_SUMMARY_HEADER)) {
    const file = summarySrc.file;
    const row = {
      line,
      engine: word(f.engine, 'engine', file, line),
      variant: word(f.variant, 'variant', file, line),
      params: word(f.params, 'params', file, line),
      split: oneOf(f.split, TOSS_SPLITS, 'split', file, line),
      status: oneOf(f.status, TOSS_SUMMARY_STATUSES, 'status', file, line),
      tosses: number(f.tosses, 'tosses', file, line, { required: true, integer: true }),
      completed: number(f.completed, 'completed', file, line, { required: true, integer: true }),
      quantity: word(f.quantity, 'quantity', file, line),
      unit: f.unit,
      mean: number(f.mean, 'mean', file, line),
      median: number(f.median, 'median', file, line),
      p90: number(f.p90, 'p90', file, line),
    };
    if (row.completed > row.tosses) throw new InputError(file, line, `completed (${row.completed}) is more than tosses (${row.tosses})`);
    row.ev = `${row.engine} ${row.variant}`;
    summary.push(row);
  }
  if (!summary.length) throw new InputError(summarySrc.file, 1, 'no rows');

  let perToss = null, planar = summary.some((r) => r.quantity.startsWith('impact'));
  const perSrc = readText(where, 'per_toss.csv');
  if (perSrc) {
    perToss = [];
    for (const { line, f } of table(perSrc, PER_TOSS_HEADER, [PER_TOSS_HEADER_PLANAR])) {
      const file = perSrc.file;
      const row = {
        line,
        toss: number(f.toss, 'toss', file, line, { required: true, integer: true }),
        split: oneOf(f.split, TOSS_SPLITS, 'split', file, line),
        engine: word(f.engine, 'engine', file, line),
        variant: word(f.variant, 'variant', file, line),
        params: word(f.params, 'params', file, line),
        status: oneOf(f.status, TOSS_STATUSES, 'status', file, line),
        run_dir: runDir(f.run_dir, file, line),
        message: f.message,
      };
      for (const h of ['samples', 'steps']) row[h] = number(f[h], h, file, line, { integer: true });
      for (const h of ['duration_s', 'pos_err_end', 'pos_err_rms', 'rot_err_end_rad', 'rot_err_rms_rad', 'wall_seconds', 'cpu_seconds'])
        row[h] = number(f[h], h, file, line);
      if ('impacts_record' in f) {
        planar = true;
        for (const h of ['impacts_record', 'impacts_run']) row[h] = number(f[h], h, file, line, { integer: true });
        for (const h of IMPACT_FIELDS) row[h] = number(f[h], h, file, line);
      }
      if (row.status === 'ok' && !(Number.isFinite(row.pos_err_end) && Number.isFinite(row.rot_err_end_rad)))
        throw new InputError(file, line, 'status ok needs finite pos_err_end and rot_err_end_rad');
      row.ev = `${row.engine} ${row.variant}`;
      perToss.push(row);
    }
  }

  let fit = null;
  const fitSrc = readText(where, 'fit.csv');
  if (fitSrc) {
    fit = [];
    for (const { line, f } of table(fitSrc, FIT_HEADER, [FIT_HEADER_POSE])) {
      const file = fitSrc.file;
      const row = { line, engine: word(f.engine, 'engine', file, line), variant: word(f.variant, 'variant', file, line),
        status: oneOf(f.status, ['ok', 'not built', 'no parameters'], 'status', file, line),
        fitted: f.fitted.split(';').filter((x) => x !== '') };
      row.bounce_dv_mean_train = 'bounce_dv_mean_train' in f ? number(f.bounce_dv_mean_train, 'bounce_dv_mean_train', file, line) : null;
      if (f.converged !== '' && f.converged !== 'true' && f.converged !== 'false')
        throw new InputError(file, line, `converged: expected true, false or empty, found '${f.converged}'`);
      row.converged = f.converged === '' ? null : f.converged === 'true';
      for (const h of ['failed_train', 'evaluations', 'train_tosses', 'train_every', 'test_tosses'])
        row[h] = number(f[h], h, file, line, { integer: true });
      for (const h of ['mu', 'restitution', 'kn', 'objective_train', 'pos_err_end_mean_train', 'rot_err_end_mean_train_rad',
        'start_mu', 'start_restitution', 'start_kn', 'start_objective_train']) row[h] = number(f[h], h, file, line);
      row.ev = `${row.engine} ${row.variant}`;
      fit.push(row);
    }
  }

  const provenance = {};
  const readme = readText(where, 'README.md');
  if (readme) {
    for (const l of readme.text.split('\n')) {
      const m = PROVENANCE.exec(l.trimEnd());
      if (m && !(m[1] in provenance)) provenance[m[1]] = m[2].replace(/`/g, '');
    }
  }
  return { at, file: summarySrc.file, summary, perToss, fit, provenance, readme: readme ? readme.file : null, planar };
}

export const TRAJECTORY_HEADER = ['t', 'body', 'x', 'y', 'z', 'qw', 'qx', 'qy', 'qz', 'vx', 'vy', 'vz', 'wx', 'wy', 'wz'];

// The samples of one body in a run directory's trajectory.csv (relative to DIR): [{t, x: [3], q: [4]}];
// null when the file does not exist.
export function readBodyTrajectory(dir, run, body) {
  const src = readText(dir, path.join(run, 'trajectory.csv'));
  if (!src) return null;
  const out = [];
  for (const { line, f } of table(src, TRAJECTORY_HEADER)) {
    if (f.body !== body) continue;
    const v = TRAJECTORY_HEADER.slice(2, 9).map((h) => number(f[h], h, src.file, line, { required: true }));
    const t = number(f.t, 't', src.file, line, { required: true });
    if (!v.every(Number.isFinite) || !Number.isFinite(t)) throw new InputError(src.file, line, 'a pose that is not finite');
    if (out.length && !(t > out[out.length - 1].t)) throw new InputError(src.file, line, `t = ${f.t} does not follow the previous sample of '${body}'`);
    out.push({ t, x: v.slice(0, 3), q: v.slice(3, 7) });
  }
  return { file: src.file, samples: out };
}

// What `polydyn compare SCENE` writes beside metrics.csv (reports/FORMATS.md): divergence.csv, impacts.csv,
// series.csv, friction.csv and compare.json; null when divergence.csv is absent (an older compare directory).
export const DIVERGENCE_HEADER = ['scene', 'engine', 'variant', 'threshold', 'chaos_factor', 'first_t', 'first_body', 'first_kind', 'first_error',
  'chaos_horizon', 'beyond_chaos_from', 'verdict'];
export const IMPACTS_HEADER = ['scene', 'engine', 'variant', 'impact', 'body_a', 'body_b', 't', 'vn_before', 'vn_after', 'restitution',
  'restitution_requested', 'tangential_speed_change', 'reference_impact'];
export const BODY_SERIES_HEADER = ['engine', 'variant', 'body', 't', 'pos_err', 'rot_err_rad', 'energy', 'max_penetration_over_size',
  'contacts', 'normal_force', 'slip_speed'];
export const FRICTION_HEADER = ['engine', 'variant', 't', 'body_a', 'body_b', 'fn', 'ft', 'slip_speed', 'mode'];
const VERDICTS = ['agrees', 'chaos', 'model', 'own_divergence', 'unknown'];

export function readCompareDetail(dir) {
  const div = readText(dir, 'divergence.csv');
  if (!div) return null;
  const ev = (f, file, line) => ({ engine: word(f.engine, 'engine', file, line), variant: word(f.variant, 'variant', file, line),
    ev: `${f.engine} ${f.variant}` });
  const divergence = table(div, DIVERGENCE_HEADER).map(({ line, f }) => {
    if (!VERDICTS.includes(f.verdict)) throw new InputError(div.file, line, `verdict: one of ${VERDICTS.join(', ')}, found '${f.verdict}'`);
    if (!['', 'position', 'rotation'].includes(f.first_kind)) throw new InputError(div.file, line, `first_kind: position, rotation or empty, found '${f.first_kind}'`);
    const r = { scene: f.scene, ...ev(f, div.file, line), first_body: f.first_body, first_kind: f.first_kind, verdict: f.verdict };
    for (const h of ['threshold', 'chaos_factor', 'first_t', 'first_error', 'chaos_horizon', 'beyond_chaos_from']) r[h] = number(f[h], h, div.file, line);
    return r;
  });
  const need = (name, header) => {
    const src = readText(dir, name);
    if (!src) throw new InputError(path.join(dir, name), 0, 'missing (divergence.csv is there: polydyn compare writes both)');
    return { src, rows: table(src, header) };
  };
  const imp = need('impacts.csv', IMPACTS_HEADER);
  const impacts = imp.rows.map(({ line, f }) => {
    const r = { ...ev(f, imp.src.file, line), body_a: f.body_a, body_b: f.body_b };
    for (const h of ['impact', 't', 'vn_before', 'vn_after', 'restitution', 'restitution_requested', 'tangential_speed_change', 'reference_impact'])
      r[h] = number(f[h], h, imp.src.file, line, { integer: h === 'impact' || h === 'reference_impact' });
    return r;
  });
  const ser = need('series.csv', BODY_SERIES_HEADER);
  const series = ser.rows.map(({ line, f }) => {
    const r = { ...ev(f, ser.src.file, line), body: f.body };
    for (const h of BODY_SERIES_HEADER.slice(3)) r[h] = number(f[h], h, ser.src.file, line, { integer: h === 'contacts' });
    return r;
  });
  const fr = need('friction.csv', FRICTION_HEADER);
  const friction = fr.rows.map(({ line, f }) => {
    if (f.mode !== 'slip' && f.mode !== 'stick') throw new InputError(fr.src.file, line, `mode: slip or stick, found '${f.mode}'`);
    const r = { ...ev(f, fr.src.file, line), body_a: f.body_a, body_b: f.body_b, mode: f.mode };
    for (const h of ['t', 'fn', 'ft', 'slip_speed']) r[h] = number(f[h], h, fr.src.file, line, { required: true });
    return r;
  });
  const cj = readText(dir, 'compare.json');
  const compare = cj ? parseJson(cj.text, cj.file) : null;
  return { divergence, impacts, series, friction, compare };
}

// The scenes of `polydyn compare SCENE_DIR --out DIR`: every sub-directory NAME of DIR with a divergence.csv,
// in byte order of the names.
export function listCompareScenes(dir) {
  let names;
  try { names = fs.readdirSync(dir, { withFileTypes: true }).filter((e) => e.isDirectory()).map((e) => e.name); } catch { return []; }
  return names.sort((a, b) => (a < b ? -1 : a > b ? 1 : 0)).filter((n) => fs.existsSync(path.join(dir, n, 'divergence.csv')));
}
