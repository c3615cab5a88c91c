// RFC 4180 CSV reader shared by the viewer (src/data.js) and the report generator
// (reports/generator/lib/csv.mjs): it reads every CSV file polydyn writes (util/csv.c: a field is quoted when
// it holds a comma, a quote, a line break or a leading or trailing blank; quotes are doubled). Fields are
// separated by commas, records by LF or CRLF; a quoted field may hold commas, line breaks and "".

// Parses `text` into records: [{line, fields: [string]}]. A final line end does not start a record; a blank
// line inside is a record of one empty field. Calls fail(line, message), which must throw, for a quote inside
// an unquoted field, text after a closing quote, a quoted field that never ends (reported at the line where it
// started) or a carriage return without a line feed.
export function parseCsvRecords(text, fail) {
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
          if (i >= n) fail(quoteLine, 'quoted field is never closed');
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
            fail(quoteLine, `the quoted field that opens here runs to line ${line} and is followed by text there (an unbalanced quote?)`);
          fail(line, 'text after a closing quote (a quote inside a field is written "")');
        }
      } else {
        let j = i;
        while (j < n && text[j] !== ',' && text[j] !== '\n' && text[j] !== '\r') {
          if (text[j] === '"') fail(line, 'quote inside an unquoted field (quote the whole field)');
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
      if (text[i + 1] !== '\n') fail(line, 'carriage return without a line feed');
      i++;
    }
    if (text[i] === '\n') { i++; line++; }
    records.push({ line: start, fields });
  }
  return records;
}
