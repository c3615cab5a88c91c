// Unit tests of the report generator's parts (node --test): the CSV and JSON readers keep line
// numbers, the cost-to-target interpolation, the matrix aggregation, the number formatting, the replay
// data shortened without changing what the viewer reads.
import test from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { parseCsv, writeCsv } from '../../reports/generator/lib/csv.mjs';
import { parseJson, lineOf } from '../../reports/generator/lib/json.mjs';
import { costToReach, isOwnReference, matrix, orderEngineVariants, median, verdicts, workPrecision } from '../../reports/generator/lib/derive.mjs';
import { readCubetoss, readPrecision, readResults, readSweep } from '../../reports/generator/lib/inputs.mjs';
import { num } from '../../reports/generator/lib/html.mjs';
import { precision } from '../../reports/generator/lib/precision.mjs';
import { parseArgs, outputPaths } from '../../reports/generator/report.mjs';
import { shortDouble, shortFloat32, compactTrajectory, compactContacts } from '../../reports/generator/lib/replay.mjs';
import { readRunFiles } from '../../viewer/src/data.js';

const HERE = path.dirname(fileURLToPath(import.meta.url));

test('csv: quoted fields keep commas, quotes and line breaks, and records keep their first line', () => {
  const recs = parseCsv('a,b\n1,"x, ""y""\nz"\r\n2,\n', 'f.csv');
  assert.deepEqual(recs.map((r) => r.line), [1, 2, 4]);
  assert.deepEqual(recs[1].fields, ['1', 'x, "y"\nz']);
  assert.deepEqual(recs[2].fields, ['2', '']);
});

test('csv: an unclosed quote is reported at the line where it opened', () => {
  assert.throws(() => parseCsv('a,b\n1,2\n3,"never\nclosed\n', 'f.csv'), { message: 'f.csv:3: quoted field is never closed' });
});

test('csv: an unbalanced quote that swallows lines is reported where it opens', () => {
  assert.throws(() => parseCsv('a,b\n1,"x\n2,y\n3,"z",\n', 'f.csv'),
    { message: 'f.csv:2: the quoted field that opens here runs to line 4 and is followed by text there (an unbalanced quote?)' });
});

test('csv: a quote inside an unquoted field and text after a closing quote are errors with their line', () => {
  assert.throws(() => parseCsv('a,b\n1,x"y\n', 'f.csv'), /^Error: f\.csv:2: quote inside an unquoted field/);
  assert.throws(() => parseCsv('a,b\n\n"q"x,1\n', 'f.csv'), /^Error: f\.csv:3: text after a closing quote/);
});

test('csv: what writeCsv writes reads back to the same fields', () => {
  const rows = [['plain', 'with, comma', 'with "quote"', 'two\nlines', ' lead', 1.5e-300, -0]];
  const back = parseCsv(writeCsv(['a', 'b', 'c', 'd', 'e', 'f', 'g'], rows), 'x');
  assert.deepEqual(back[1].fields, ['plain', 'with, comma', 'with "quote"', 'two\nlines', ' lead', '1.5e-300', '0']);
});

test('json: objects and arrays remember their line; errors give the line', () => {
  const v = parseJson('[\n  {"a": 1},\n\n  {"b": [\n 2]}\n]\n', 'e.json');
  assert.equal(lineOf(v), 1);
  assert.equal(lineOf(v[0]), 2);
  assert.equal(lineOf(v[1]), 4);
  assert.equal(lineOf(v[1].b), 4);
  assert.throws(() => parseJson('{\n "a": 1,\n "b": tru\n}', 'e.json'), /^Error: e\.json:3: malformed JSON/);
  assert.throws(() => parseJson('{"a": 1, "a": 2}', 'e.json'), /e\.json:1: duplicate member "a"/);
});

test('json: numbers and strings decode exactly as JSON.parse does', () => {
  const text = '{"x": 0.29999999999999993, "y": -1.5e-310, "s": "\\u00e9\\n\\"", "big": 1e308}';
  assert.deepEqual(parseJson(text, 'f'), JSON.parse(text));
});

test('costToReach: interpolates linearly in log error and log cost between the points around the target', () => {
  const pts = [{ value: 1e-2, error: 1e-1, wall_per_sim_second: 1e-3 }, { value: 1e-3, error: 1e-4, wall_per_sim_second: 1e-1 }];
  const c = costToReach(pts, 1e-3);
  assert.equal(c.kind, 'interpolated');
  // error falls 3 decades over 2 decades of cost: 1e-3 is 2/3 of the way: cost 10^(-3 + 4/3)
  assert.ok(Math.abs(Math.log10(c.wall_per_sim_second) - (-3 + 4 / 3)) < 1e-12);
});

test('sweep.csv: the header with the derivative counts, the one before (self-convergence last) and the first all load', () => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'pd-units-'));
  try {
    const old = 'scene,engine,variant,setting,value,error,error_kind,wall_seconds,wall_per_sim_second,steps,repeats,reference';
    const rows = (scene, own) => [
      `${scene},ode,native,step,0.004,0.05,rms_pose,0.01,0.01,300,3,soft tol=1e-12${own ? ',0.02,ode native step=0.001,0.5' : ''}`,
      `${scene},ode,native,step,0.001,0.05,rms_pose,0.04,0.04,1000,3,soft tol=1e-12${own ? ',,ode native step=0.001,' : ''}`];
    fs.writeFileSync(path.join(dir, 'sweep.csv'), [old, ...rows('a', false)].join('\n') + '\n');
    const a = readSweep(dir);
    assert.deepEqual(a.rows.map((r) => [r.has_self, r.self_error, r.self_reference, r.horizon_seconds]), [[false, null, null, null], [false, null, null, null]]);
    const wpOld = workPrecision(a);
    assert.equal(wpOld[0].self_convergence, false);
    assert.equal(wpOld[0].curves[0].to_target.kind, 'never');  // read on error: 0.05 never reaches 1e-3
    fs.writeFileSync(path.join(dir, 'sweep.csv'), [`${old},self_error,self_reference,horizon_seconds`, ...rows('b', true), old, ...rows('a', false)].join('\n') + '\n');
    const b = readSweep(dir);
    assert.deepEqual(b.rows.map((r) => [r.scene, r.has_self, r.self_error, r.horizon_seconds]),
      [['b', true, 0.02, 0.5], ['b', true, null, null], ['a', false, null, null], ['a', false, null, null]]);
    fs.writeFileSync(path.join(dir, 'sweep.csv'), [`${old},self_error,self_reference,horizon_seconds,derivatives`,
      'c,soft,embedded,tol,1e-06,0.001,rms_pose,0.01,0.01,300,3,soft tol=1e-12,0.001,soft tol=1e-12,,1500',
      'c,ode,native,step,0.001,0.05,rms_pose,0.04,0.04,1000,3,soft tol=1e-12,,ode native step=0.001,,'].join('\n') + '\n');
    assert.deepEqual(readSweep(dir).rows.map((r) => [r.scene, r.variant, r.derivatives, r.has_self]),
      [['c', 'embedded', 1500, true], ['c', 'native', null, true]]);
    fs.writeFileSync(path.join(dir, 'sweep.csv'), [`${old},self_error,self_reference,horizon_seconds`, ...rows('b', true), old, ...rows('a', false)].join('\n') + '\n');
    const wp = workPrecision(readSweep(dir));
    assert.equal(wp[0].self_convergence, true);
    assert.equal(wp[0].has_horizon, true);
    assert.equal(wp[0].curves[0].to_target.kind, 'never');  // 0.02 is the only self_error: above 1e-3
    assert.deepEqual(wp[0].curves[0].self_references, ['ode native step=0.001']);
    assert.equal(isOwnReference(wp[0].curves[0], wp[0].curves[0].points[1]), true);
    assert.equal(isOwnReference(wp[0].curves[0], wp[0].curves[0].points[0]), false);
    assert.equal(wp[1].self_convergence, false);
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
});

test('workPrecision: the cost is read on self_error where the sweep has it, and on error for to_target_reference', () => {
  const row = (value, error, self, wps) => ({ scene: 's', engine: 'ode', variant: 'native', ev: 'ode native', setting: 'step', value, error,
    self_error: self, wall_per_sim_second: wps, has_self: true, self_reference: 'ode native step=0.0001', horizon_seconds: null });
  const wp = workPrecision({ rows: [row(0.01, 0.05, 1e-2, 1), row(0.001, 0.05, 1e-4, 10), row(0.0001, 0.05, null, 100)] });
  const c = wp[0].curves[0];
  assert.equal(c.to_target.kind, 'interpolated');
  assert.ok(Math.abs(c.to_target.wall_per_sim_second - Math.sqrt(10)) < 1e-12);  // halfway in log between 1e-2 and 1e-4
  assert.equal(c.to_target_reference.kind, 'never');
  assert.equal(wp[0].has_horizon, false);
});

test('costToReach: "at_most" when the loosest usable point is already there, "never" when none is, failed points skipped', () => {
  assert.deepEqual(costToReach([{ value: 1, error: null, wall_per_sim_second: 1 }, { value: 0.1, error: 1e-4, wall_per_sim_second: 2 }], 1e-3),
    { kind: 'at_most', wall_per_sim_second: 2, setting_value: 0.1 });
  assert.equal(costToReach([{ value: 1, error: 0.1, wall_per_sim_second: 1 }, { value: 0.1, error: 0.01, wall_per_sim_second: 2 }], 1e-3).kind, 'never');
  assert.equal(costToReach([], 1e-3).kind, 'never');
});

test('matrix: a cell over several inputs has the worst status, the passing count and the largest error', () => {
  const row = (input, status, error, tolerance) => ({ experiment: 'A1', engine: 'ode', variant: 'native', ev: 'ode native', input,
    inputValue: Number(input.split('=')[1]), status, error, tolerance, relative: false, wall_seconds: 1, line: 2 });
  const m = matrix({ rows: [row('e=0.3', 'PASS', 0.001, 0.005), row('e=0.5', 'FAIL', 0.02, 0.005), row('e=0.8', 'ERROR', null, 0.005)] }, null);
  assert.equal(m.cells.length, 1);
  const c = m.cells[0];
  assert.equal(c.status, 'ERROR');
  assert.equal(c.passed, 1);
  assert.equal(c.inputs, 3);
  assert.equal(c.error, 0.02);
  assert.equal(c.error_over_tolerance, 4);
  assert.equal(c.worst_input, 'e=0.5');
  assert.equal(c.wall_seconds, 3);
});

test('verdict: a model prediction on a variant it does not apply to is n/a, never a pass or a failure', () => {
  const row = (experiment, ev, status, error, note = '') => ({ experiment, engine: ev.split(' ')[0], variant: ev.split(' ')[1], ev,
    input: '', inputValue: null, status, error, tolerance: 0.01, relative: true, wall_seconds: 1, line: 2, note });
  const results = { rows: [
    row('a3_sinkage', 'soft adaptive', 'PASS', 1e-9), row('a3_sinkage', 'ode native', 'NOT_APPLICABLE', 1, 'not applicable: a rigid contact does not sink; relative'),
    row('b2_stop_time', 'soft adaptive', 'PASS', 1e-3), row('b2_stop_time', 'ode native', 'FAIL', 0.5)] };
  const experiments = { list: [{ name: 'a3_sinkage', group: 'A', kind: 'model_prediction', not_applicable_reason: 'rigid: no sinkage' },
    { name: 'b2_stop_time', group: 'B', kind: 'law' }] };
  const m = matrix(results, experiments);
  const na = m.cells.find((c) => c.ev === 'ode native' && c.experiment === 'a3_sinkage');
  assert.equal(na.status, 'NOT_APPLICABLE');
  assert.equal(na.not_applicable_reason, 'rigid: no sinkage');
  assert.equal(matrix(results, null).cells.find((c) => c === na || (c.ev === 'ode native' && c.experiment === 'a3_sinkage')).not_applicable_reason,
    'a rigid contact does not sink', 'without experiments.json the reason comes from the note');
  const [soft, ode] = verdicts(m);
  assert.deepEqual([soft.pass, soft.experiments, soft.not_applicable], [2, 2, []]);
  // ODE: 0 of 1 applicable; its 100 × tolerance error on the sinkage is not its worst judged error
  assert.deepEqual([ode.pass, ode.experiments, ode.fail, ode.not_applicable], [0, 1, ['b2_stop_time'], ['a3_sinkage']]);
  assert.equal(ode.worst.experiment, 'b2_stop_time');
});

test('engine-variants are ordered soft, ode, bullet, then others; adaptive, native, matched within one', () => {
  const evs = [['bullet', 'matched'], ['zeta', 'native'], ['ode', 'native'], ['bullet', 'native'], ['soft', 'adaptive'], ['ode', 'matched']]
    .map(([engine, variant]) => ({ engine, variant, ev: `${engine} ${variant}` }));
  assert.deepEqual(orderEngineVariants(evs).map((x) => x.ev),
    ['soft adaptive', 'ode native', 'ode matched', 'bullet native', 'bullet matched', 'zeta native']);
});

test('median of an even count is the mean of the middle two; non-finite values are left out', () => {
  assert.equal(median([4, 1, NaN, 3, 2]), 2.5);
  assert.equal(median([]), null);
});

test('numbers read with 3 significant digits, scientific outside [1e-3, 1e5)', () => {
  assert.equal(num(0.50968), '0.51');
  assert.equal(num(0.5097, 4), '0.5097');
  assert.equal(num(1.23456e-7), '1.23e-7');
  assert.equal(num(2e6), '2e6');
  assert.equal(num(0), '0');
  assert.equal(num(null), '—');
  assert.equal(num(NaN), 'nan');
});

test('arguments: DIR, -o, --viewer, --no-viewer; outputs beside the page', () => {
  assert.deepEqual(parseArgs(['d', '-o', 'x/r.html', '--no-viewer']), { dir: 'd', out: 'x/r.html', viewer: null });
  assert.throws(() => parseArgs([]), /DIR is missing/);
  assert.throws(() => parseArgs(['a', 'b']), /one directory expected/);
  assert.throws(() => parseArgs(['a', '--bogus']), /unknown option/);
  assert.deepEqual(outputPaths('d', null, ['matrix']), { page: 'd/report.html', json: 'd/report.json', csv: { matrix: 'd/report-matrix.csv' },
    replays: 'd/report-replays' });
  assert.equal(outputPaths('d', 'out/x.html', []).json, 'out/x.json');
  assert.equal(outputPaths('d', 'out/x.html').replays, 'out/x-replays');
});

import { rotationAngle, errorsOverTime, ecdf, typicalToss, paramsOrder } from '../../reports/generator/lib/cubetoss.mjs';

test('cube tosses: rotation angle of q_ref⁻¹ q is the angle between orientations, whatever the sign of q', () => {
  const about = (deg, axis) => { const h = deg * Math.PI / 360; return [Math.cos(h), ...axis.map((c) => Math.sin(h) * c)]; };
  const ref = about(30, [0, 0, 1]);
  assert.ok(Math.abs(rotationAngle(about(120, [0, 0, 1]), ref) - Math.PI / 2) < 1e-15);
  assert.ok(Math.abs(rotationAngle(about(120, [0, 0, 1]).map((c) => -c), ref) - Math.PI / 2) < 1e-15);
  // small angles keep their digits (an arccos of the scalar part would be off by ~1e-8 rad here)
  const small = 1e-7 * Math.PI / 180;
  assert.ok(Math.abs(rotationAngle(about(30 + 1e-7, [0, 0, 1]), ref) - small) < 1e-6 * small);
  assert.equal(rotationAngle(ref, ref), 0);
});

test('cube tosses: errors over time use only run samples at the record\'s times, positions in widths', () => {
  const s = (t, x) => ({ t, x: [x, 0, 0], q: [1, 0, 0, 0] });
  const rec = [s(0, 0), s(1, 0), s(2, 0)];
  const run = [s(0, 0.1), s(0.5, 9), s(1 + 1e-12, 0.2), s(2.5, 9)];
  assert.deepEqual(errorsOverTime(rec, run, 0.1).map((e) => [e.t, Math.round(e.pos * 1e12) / 1e12]), [[0, 1], [1, 2]]);
});

test('cube tosses: the typical toss is nearest the median, among tosses with a replay, ties to the lower toss', () => {
  const row = (toss, e) => ({ toss, split: 'test', engine: 'soft', variant: 'adaptive', ev: 'soft adaptive', params: 'fitted', status: 'ok', pos_err_end: e });
  const rows = [row(5, 0.125), row(3, 0.25), row(9, 0.75), row(7, 1), row(1, 0.5)];  // median 0.5 (exact binary fractions)
  assert.equal(typicalToss(rows, { params: 'fitted', split: 'test' }, () => true).toss, 1);
  assert.equal(typicalToss(rows, { params: 'fitted', split: 'test' }, (t) => t !== 1).toss, 3, '0.25 and 0.75 tie: toss 3');
  const none = typicalToss(rows, { params: 'fitted', split: 'test' }, () => false);
  assert.equal(none.toss, 1);
  assert.equal(none.replay, false);
  assert.deepEqual(ecdf([3, 1, 2, NaN]), [[1, 1 / 3], [2, 2 / 3], [3, 1]]);
  assert.deepEqual(paramsOrder([{ params: 'x' }, { params: 'fitted' }, { params: 'default' }]), ['default', 'fitted', 'x']);
});

test('replay data: each number shortened to the shortest text of the value the viewer keeps, other fields as they are', () => {
  assert.equal(shortDouble('0.55000000000000004'), '0.55');
  assert.equal(shortDouble('-5.5511151231257827e-17'), '-5.551115123125783e-17');
  assert.equal(shortDouble('-0'), '-0');
  for (const field of ['', ' 1', 'nan', 'inf', 'box', '1e999']) {
    assert.equal(shortDouble(field), field);
    assert.equal(shortFloat32(field), field);
  }
  assert.equal(shortFloat32('-0.0098100000000000001'), '-0.00981');  // float32(-0.00981) is the same float32
  assert.equal(shortFloat32('0.10000000149011612'), '0.1');
  assert.equal(shortFloat32('16777217'), '16777216');  // 2^24 + 1 is not a float32
});

test('replay data: the viewer reads the shortened files of a run into the very same arrays, to the bit', () => {
  const dir = path.join(HERE, 'fixtures', 'gedanken', 'runs', 'A1', 'soft-adaptive-e=0.5');
  // the bodies of the run (floor, box) as summary.json describes them today (the fixture's is older)
  const cube = { vertices: [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]],
    faces: [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [0, 4, 7, 3]] };
  const body = (name, fixed) => ({ name, color: 'grey', fixed, mass: 1, size: 2, inertia: [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
    initial: { x: [0, 0, 0], q: [1, [0, 0, 0]] }, shape: cube });
  const summary = { engine: 'soft', scene: 's', settings: { gravity: [0, 0, -9.81] }, bodies: [body('floor', true), body('box', false)] };
  const trajectory = fs.readFileSync(path.join(dir, 'trajectory.csv'), 'utf8');
  // contacts at three sample times, numbers written as polydyn does (%.17g), from a fixed generator
  const times = trajectory.split('\n').slice(1, 4).map((l) => l.split(',')[0]);
  let seed = 7;
  const random = () => { seed = (seed * 16807) % 2147483647; return (seed / 2147483647 - 0.5) * 10 ** ((seed % 9) - 4); };
  const g17 = (x) => x.toPrecision(17);
  const contacts = 't,body_a,body_b,kind,feat_a,feat_b,px,py,pz,nx,ny,nz,fn,ftx,fty,ftz,mode\n' +
    times.map((t, k) => [t, 'box', 'floor', k ? 'EE' : 'VF', 3, 1, ...Array.from({ length: 10 }, () => g17(random())), k ? 'slip' : 'stick'].join(',') + '\n').join('');
  const full = { run: 'r', summary, trajectory, contacts };
  const short = { ...full, trajectory: compactTrajectory(trajectory), contacts: compactContacts(contacts) };
  assert.ok(short.trajectory.length < 0.8 * trajectory.length && short.contacts.length < contacts.length,
    `${trajectory.length} → ${short.trajectory.length}, ${contacts.length} → ${short.contacts.length} bytes`);
  const [a, b] = [readRunFiles(full).runs[0], readRunFiles(short).runs[0]];
  assert.equal(a.contacts, 3);
  const bytes = (v) => Buffer.from(v.buffer, v.byteOffset, v.byteLength);
  for (const k of ['t', 'pose', 'vel', 'contactStart', 'contactFloat', 'contactInt']) assert.ok(bytes(a[k]).equals(bytes(b[k])), k);
});

test('precision: the cost to the tolerance per curve; "never" stalls or still falls; not built and n/a are not counted', () => {
  const row = (engine, variant, value, error, wall, extra = {}) => ({ experiment: 'x1', kind: 'law', engine, variant, ev: `${engine} ${variant}`,
    setting: 'step', value, input: '', quantity: 'q', unit: '', measured: 1, expected: 1, error, relative: false, tolerance: 0.01,
    judged: true, status: 'ok', wall_seconds: wall, wall_per_sim_second: wall, steps: 10, repeats: 1, note: '', ...extra });
  const rows = [
    row('soft', 'adaptive', 1e-2, 1, 1), row('soft', 'adaptive', 1e-3, 1e-4, 100),        // crosses 0.01 at 10
    row('ode', 'native', 1e-2, 0.5, 1), row('ode', 'native', 1e-3, 0.3, 2), row('ode', 'native', 1e-4, 0.29, 4),  // stalls
    row('ode', 'matched', 1e-2, 0.5, 1), row('ode', 'matched', 1e-3, 0.1, 2),              // still falling
    row('bullet', 'native', null, null, null, { setting: '', status: 'not_built' }),
    row('bullet', 'matched', 1e-2, 1e-3, 3, { judged: false }),                            // reaches it, but n/a
  ];
  const p = precision({ rows }, null);
  const c = Object.fromEntries(p.experiments[0].curves.map((x) => [x.ev, x]));
  assert.equal(c['soft adaptive'].to_tolerance.kind, 'interpolated');
  assert.ok(Math.abs(c['soft adaptive'].to_tolerance.wall_per_sim_second - 10) < 1e-9);
  assert.deepEqual([c['ode native'].never.why, c['ode native'].floor], ['stalls', 0.29]);
  assert.deepEqual([c['ode matched'].never.why, c['ode matched'].floor], ['still_falling', 0.1]);
  assert.equal(c['bullet native'].to_tolerance.kind, 'not_built');
  const s = Object.fromEntries(p.summary.map((x) => [x.ev, x]));
  assert.deepEqual([s['soft adaptive'].judged, s['soft adaptive'].reached], [1, 1]);
  assert.deepEqual(s['ode native'].never, ['x1']);
  assert.deepEqual([s['bullet native'].judged, s['bullet native'].not_built], [0, true]);
  assert.deepEqual([s['bullet matched'].judged, s['bullet matched'].not_applicable], [0, ['x1']]);
});

// The main job (scripts/gedanken-report) reads the committed results beside its own run: a schema change in a
// writer must reach the readers before the regenerated results are committed.
test('the committed reports load: reports/sweep, reports/gedanken, reports/cubetoss', () => {
  const root = path.join(HERE, '..', '..', 'reports');
  assert.ok(readSweep(path.join(root, 'sweep')).rows.length > 0);
  assert.ok(readResults(path.join(root, 'gedanken')).rows.length > 0);
  assert.ok(readPrecision(path.join(root, 'gedanken')).rows.length > 0);
  assert.ok(readCubetoss(path.join(root, 'cubetoss')) !== null);
});

test('costToReach: a point within the target between two outside it is luck; a setting that gave no answer is outside it', () => {
  // 3e-2 within, 1e-2 outside, 1e-3 and finer within: the crossing is between 1e-2 and 1e-3, not at 3e-2
  const lucky = [{ value: 1e-1, error: 4, wall_per_sim_second: 1 }, { value: 3e-2, error: 0.4, wall_per_sim_second: 1 },
    { value: 1e-2, error: 4, wall_per_sim_second: 1 }, { value: 1e-3, error: 0.1, wall_per_sim_second: 10 },
    { value: 1e-4, error: 0.1, wall_per_sim_second: 20 }];
  const c = costToReach(lucky, 1);
  assert.equal(c.kind, 'interpolated');
  assert.ok(c.wall_per_sim_second > 1 && c.wall_per_sim_second < 10);
  // a frozen run (error 200 at cost 0.1) before an exact one must not pull the crossing down to ~0.15: no answer
  // (Infinity) is not interpolated from, and a wrong answer only bounds it
  const noAnswer = [{ value: 1e-1, error: Infinity, wall_per_sim_second: null }, { value: 3e-2, error: 1e-13, wall_per_sim_second: 1 },
    { value: 1e-2, error: 1e-13, wall_per_sim_second: 1.1 }];
  assert.deepEqual(costToReach(noAnswer, 1e-2), { kind: 'at_most', wall_per_sim_second: 1, setting_value: 3e-2 });
  const frozen = [{ value: 1e-1, error: 2, wall_per_sim_second: 0.1 }, ...noAnswer.slice(1)];
  assert.deepEqual(costToReach(frozen, 1e-2), { kind: 'at_most', wall_per_sim_second: 1, setting_value: 3e-2 });
  // the finest point within the target counts (nothing finer to contradict it)
  assert.equal(costToReach([{ value: 1e-2, error: 2, wall_per_sim_second: 1 }, { value: 1e-3, error: 0.5, wall_per_sim_second: 4 }], 1).kind,
    'interpolated');
  assert.equal(costToReach([{ value: 1e-2, error: 0.5, wall_per_sim_second: 1 }, { value: 1e-3, error: Infinity, wall_per_sim_second: null }], 1).kind,
    'never');
});
