// pdutil — the CSV field writer and record reader (pdutil/csv.h).
#include "pdutil/csv.h"

#include <math.h>
#include <string.h>

static bool is_blank(char c) { return c == ' ' || c == '\t'; }

bool pdu_csv_needs_quotes(const char* s) {
  if (!*s) return false;
  return strpbrk(s, ",\"\r\n") != NULL || is_blank(s[0]) || is_blank(s[strlen(s) - 1]);
}

void pdu_csv_quoted(FILE* out, const char* s) {
  fputc('"', out);
  for (; *s; ++s) {
    if (*s == '"') fputc('"', out);
    fputc(*s, out);
  }
  fputc('"', out);
}

void pdu_csv_text(FILE* out, const char* s) {
  if (pdu_csv_needs_quotes(s))
    pdu_csv_quoted(out, s);
  else
    fputs(s, out);
}

void pdu_csv_number(FILE* out, double v, int digits) {
  if (isfinite(v)) fprintf(out, "%.*g", digits, v);
}

pduCsvCursor pdu_csv_cursor(char* text) {
  if ((unsigned char)text[0] == 0xef && (unsigned char)text[1] == 0xbb && (unsigned char)text[2] == 0xbf) text += 3;
  return (pduCsvCursor){text, text, 1};
}

static int fail(pduCsvError* e, const pduCsvCursor* c, const char* at, const char* message) {
  e->line = c->line;
  e->col = (int)(at - c->lineStart) + 1;
  e->message = message;
  return -1;
}

int pdu_csv_next(pduCsvCursor* c, char** fields, int* cols, int max, int* line, pduCsvError* error) {
  char* p = c->p;
  if (*p == '\0') return 0;
  if (line) *line = c->line;
  int n = 0;
  for (;;) {
    if (n == max) return fail(error, c, p, "too many fields");
    if (cols) cols[n] = (int)(p - c->lineStart) + 1;
    fields[n] = p;
    if (*p == '"') {
      // quoted: unquote in place (the text only shrinks)
      char* w = p;
      char* r = p + 1;
      pduCsvCursor open = *c;
      for (;; ++r) {
        if (*r == '\0') return fail(error, &open, p, "quoted field is never closed");
        if (*r == '"') {
          if (r[1] != '"') break;
          ++r;
        } else if (*r == '\n') {
          c->line++;
          c->lineStart = r + 1;
        }
        *w++ = *r;
      }
      ++r;  // past the closing quote
      if (*r != ',' && *r != '\n' && *r != '\r' && *r != '\0')
        return fail(error, c, r, "text after a closing quote (a quote inside a field is written \"\")");
      *w = '\0';  // w < r: the terminator never overwrites the separator
      p = r;
    } else {
      p += strcspn(p, ",\"\r\n");
      if (*p == '"') return fail(error, c, p, "quote inside an unquoted field (quote the whole field)");
    }
    ++n;
    char sep = *p;
    if (sep == ',') {
      *p++ = '\0';
      continue;
    }
    if (sep == '\r') {
      if (p[1] != '\n') return fail(error, c, p, "carriage return without a line feed");
      *p++ = '\0';
      sep = '\n';
    }
    if (sep == '\n') {
      *p++ = '\0';
      c->line++;
      c->lineStart = p;
    }
    c->p = p;
    return n;
  }
}
