// Reads back what polydyn wrote for a scene with unusual names, with the project's own JavaScript readers
// (the report generator's parseCsv, the viewer's readRunFiles), and checks each name byte for byte.
// Usage: node names_check.mjs NAMES.json RUN_DIR COMPARE_DIR [SWEEP_DIR SCENE_PATH]
//   NAMES.json  the moving bodies' names in scene order (what the scene was written with)
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { parseCsv } from '../../reports/generator/lib/csv.mjs';
import { readRunFiles } from '../../viewer/src/data.js';

const [namesFile, runDir, compareDir, sweepDir, scenePath] = process.argv.slice(2);
const names = JSON.parse(fs.readFileSync(namesFile, 'utf8'));
const read = (dir, file) => fs.readFileSync(path.join(dir, file), 'utf8');

// run: trajectory.csv's body column, summary.json's bodies, contacts.csv's bodies
const trajectory = parseCsv(read(runDir, 'trajectory.csv'), 'trajectory.csv');
const firstSample = trajectory.slice(1, 1 + names.length).map((r) => r.fields[1]);
assert.deepEqual(firstSample, names, 'trajectory.csv: the body column, first sample');
const summary = JSON.parse(read(runDir, 'summary.json'));
assert.deepEqual(summary.bodies.filter((b) => !b.fixed).map((b) => b.name), names, 'summary.json: bodies');
const contacts = parseCsv(read(runDir, 'contacts.csv'), 'contacts.csv');
const known = new Set(summary.bodies.map((b) => b.name));
for (const r of contacts.slice(1)) assert.ok(known.has(r.fields[1]) && known.has(r.fields[2]), `contacts.csv:${r.line}`);
// the viewer's reader of the same files
const view = readRunFiles({ run: runDir, summary, trajectory: read(runDir, 'trajectory.csv'),
  contacts: read(runDir, 'contacts.csv') });
assert.deepEqual(view.runs[0].bodies.filter((b) => !b.fixed).map((b) => b.name), names, 'viewer: bodies');

// compare: metrics.csv's restitution_impacts names every body that bounced, as NAME:e;NAME:e
const metrics = parseCsv(read(compareDir, 'metrics.csv'), 'metrics.csv');
const header = metrics[0].fields;
const impacts = metrics.slice(1).map((r) => r.fields[header.indexOf('restitution_impacts')]);
assert.ok(metrics.length > 1 && metrics.slice(1).every((r) => r.fields.length === header.length), 'metrics.csv: rows');
const bounced = new Set();
for (const field of impacts)
  for (const name of names) if (field.includes(`${name}:`)) bounced.add(name);
assert.ok(bounced.size > 0, `metrics.csv: no body's name in restitution_impacts (${impacts[0]})`);
JSON.parse(read(compareDir, 'compare.json'));

if (sweepDir) {
  const sweep = parseCsv(read(sweepDir, 'sweep.csv'), 'sweep.csv');
  const scene = sweep[0].fields.indexOf('scene');
  for (const r of sweep.slice(1)) assert.equal(r.fields[scene], scenePath, `sweep.csv:${r.line}: scene`);
  assert.equal(JSON.parse(read(sweepDir, 'reference.json')).scene, scenePath, 'reference.json: scene');
}
console.log(`${names.length} names read back; ${bounced.size} in restitution_impacts`);
