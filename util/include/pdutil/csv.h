// pdutil — CSV (RFC 4180): the one field writer of every CSV file polydyn writes, and the one record
// reader of its C readers.
//
// Writing: a text field is written as it is unless it holds a comma, a double quote, a carriage return or
// a line feed, or begins or ends with a blank (space or tab, which spreadsheet readers trim); then it is
// written in double quotes with each quote doubled. Records end with LF. Numbers are written by the
// caller's format; pdu_csv_number covers the common "%.Ng, empty when not finite".
//
// Reading: pdu_csv_next takes one record from a mutable NUL-terminated text, unquotes its fields in place
// and returns them with their line and 1-based byte column; a quoted field may span lines. Records end with
// LF or CRLF.
#pragma once

#include <stdbool.h>
#include <stdio.h>

// Whether `s` must be quoted to stay one field.
bool pdu_csv_needs_quotes(const char* s);

// Writes `s` as one field: quoted only when it needs it.
void pdu_csv_text(FILE* out, const char* s);

// Writes `s` as one field, always quoted (for a column that is quoted in every row).
void pdu_csv_quoted(FILE* out, const char* s);

// Writes `v` with `digits` significant digits (%.*g), or nothing (an empty field) when v is not finite.
void pdu_csv_number(FILE* out, double v, int digits);

typedef struct pduCsvCursor {
  char* p;          // next unread byte
  char* lineStart;  // start of the line p is on (for columns)
  int line;         // 1-based line of p
} pduCsvCursor;

// A cursor at the start of `text` (NUL-terminated; pdu_csv_next writes into it). A byte-order mark is skipped.
pduCsvCursor pdu_csv_cursor(char* text);

typedef struct pduCsvError {
  int line, col;       // where the record went wrong
  const char* message; // static text
} pduCsvError;

// Reads the next record into fields[0..max-1] (pointers into the text) with each field's line start column
// in cols (may be NULL) and its line in *line (may be NULL). Returns the number of fields, 0 at the end of
// the text, or -1 with *error filled: a quote inside an unquoted field, text after a closing quote, a quoted
// field never closed, more than `max` fields, or a carriage return without a line feed.
int pdu_csv_next(pduCsvCursor* c, char** fields, int* cols, int max, int* line, pduCsvError* error);
