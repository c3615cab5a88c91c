// The JavaScript readers of polydyn's CSV files (viewer/src/csv.js, which the viewer and the report generator
// share, and the generator's parseCsv) read back every record util/csv.c wrote, byte for byte: fields.csv
// against the same records in fields.json (util/json.c's strings, parsed by JSON.parse).
// Usage: node check_readers.mjs DIR
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { parseCsvRecords } from '../../viewer/src/csv.js';
import { parseCsv } from '../../reports/generator/lib/csv.mjs';

const dir = process.argv[2];
const csv = fs.readFileSync(path.join(dir, 'fields.csv'), 'utf8');
const expected = JSON.parse(fs.readFileSync(path.join(dir, 'fields.json'), 'utf8'));
const viaViewer = parseCsvRecords(csv, (line, message) => { throw new Error(`fields.csv:${line}: ${message}`); });
const viaReport = parseCsv(csv, 'fields.csv');
for (const records of [viaViewer, viaReport]) {
  assert.equal(records.length, expected.length);
  records.forEach((r, i) => assert.deepEqual(r.fields, expected[i], `record ${i + 1} (line ${r.line})`));
}
const fields = expected.flat();
console.log(`${expected.length} records, ${fields.length} fields (longest ${Math.max(...fields.map((f) => f.length))} characters) read back by both readers`);
