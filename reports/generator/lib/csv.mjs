// RFC 4180 CSV: a reader that keeps the line each record starts on (for FILE:LINE messages) and a
// writer. Fields are separated by commas, records by LF or CRLF; a field in double quotes may hold
// commas, line breaks and doubled quotes ("").
import { InputError } from './errors.mjs';

// Parses `text` (the contents of `file`) into records: [{line, fields: [string]}]. A final line end
// does not start a record; a blank line inside is a record of one empty field. Throws InputError(file, line, ...) for a quote inside an unquoted field, text after
// a closing quote, or a quoted field that never ends (reported at the line where it started).
export function parseCsv(text, file) {
  const records = [];
  const n = text.length;
  let i = 0;
  let line = 1;
  if (text.charCodeAt(0) === 0xfeff) i = 1;  // byte-order mark
  while (i < n) {
    const start = line;
    const fields = [];
    for (;;) {
      // one field
      let value = '';
      if (text[i] === '"') {
        const quoteLine = line;
        i++;
        for (;;) {
          if (i >= n) throw new InputError(file, quoteLine, 'quoted field is never closed');
          const c = text[i];
          if (c === '"') {
            if (text[i + 1] === '"') { value += '"'; i += 2; continue; }
            i++;
            break;
          }
          if (c === '\n') line++;
          value += c;
          i++;
        }
        if (i < n && text[i] !== ',' && text[i] !== '\n' && text[i] !== '\r') {
          if (quoteLine !== line)
            throw new InputError(file, quoteLine, `the quoted field that opens here runs to line ${line} and is followed by text there (an unbalanced quote?)`);
          throw new InputError(file, line, 'text after a closing quote (a quote inside a field is written "")');
        }
      } else {
        let j = i;
        while (j < n && text[j] !== ',' && text[j] !== '\n' && text[j] !== '\r') {
          if (text[j] === '"') throw new InputError(file, line, 'quote inside an unquoted field (quote the whole field)');
          j++;
        }
        value = text.slice(i, j);
        i = j;
      }
      fields.push(value);
      if (i < n && text[i] === ',') { i++; continue; }
      break;
    }
    // end of record: CRLF, LF or end of text
    if (text[i] === '\r') {
      if (text[i + 1] !== '\n') throw new InputError(file, line, 'carriage return without a line feed');
      i++;
    }
    if (text[i] === '\n') { i++; line++; }
    records.push({ line: start, fields });
  }
  return records;
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
