// RFC 4180 CSV: the shared reader (viewer/src/csv.js) with FILE:LINE messages, and a writer. Fields are separated by commas, records by LF or CRLF; a field in double quotes may hold
// commas, line breaks and doubled quotes ("").
import { InputError } from './errors.mjs';
import { parseCsvRecords } from '../../../viewer/src/csv.js';

// Parses `text` (the contents of `file`) into records: [{line, fields: [string]}] (viewer/src/csv.js, which
// the viewer reads run directories with). Throws InputError(file, line, ...) for malformed text.
export function parseCsv(text, file) {
  return parseCsvRecords(text, (line, message) => { throw new InputError(file, line, message); });
}

// Quotes a field when it needs it (comma, quote, CR or LF, or leading/trailing space).
export function csvField(value) {
  const s = value === null || value === undefined ? '' : typeof value === 'number' ? formatNumber(value) : String(value);
  return /[",\r\n]|^\s|\s$/.test(s) ? '"' + s.replace(/"/g, '""') + '"' : s;
}

// A number as text that reads back to the same double (JavaScript's shortest round-trip form);
// non-finite numbers as nan, inf, -inf (what C's %.17g prints).
export function formatNumber(x) {
  if (Number.isNaN(x)) return 'nan';
  if (x === Infinity) return 'inf';
  if (x === -Infinity) return '-inf';
  return String(x);
}

// Header + rows (arrays) as CSV text with LF line ends.
export function writeCsv(header, rows) {
  const lines = [header.map(csvField).join(',')];
  for (const r of rows) lines.push(r.map(csvField).join(','));
  return lines.join('\n') + '\n';
}
