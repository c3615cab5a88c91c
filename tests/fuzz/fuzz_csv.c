// libFuzzer target for the shared CSV and JSON writers (util/: pdutil/csv.h, pdutil/json.h), the code every
// CSV and JSON file polydyn writes goes through. The input is a record: fields separated by NUL bytes. Each
// field written by pdu_csv_text must read back the same through pdu_csv_next (the C readers' record reader),
// and each written by pdu_json_string must be a JSON string (quoted, no raw control byte, valid UTF-8) that
// decodes to the field itself when the field is valid UTF-8.
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pdutil/csv.h"
#include "pdutil/json.h"
#include "pdutil/utf8.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

enum { FIELDS_MAX = 64 };

// Decodes the escapes pdu_json_string writes (\" \\ \u00XX \ufffd); false for anything else.
static bool json_decode(const char* s, size_t n, char* out, size_t* outLength) {
  if (n < 2 || s[0] != '"' || s[n - 1] != '"') return false;
  size_t o = 0;
  for (size_t i = 1; i + 1 < n; ++i) {
    unsigned char c = (unsigned char)s[i];
    if (c < 0x20 || c == '"') return false;
    if (c != '\\') {
      out[o++] = (char)c;
      continue;
    }
    if (i + 2 >= n) return false;
    char e = s[++i];
    if (e == '"' || e == '\\') {
      out[o++] = e;
    } else if (e == 'u' && i + 5 < n) {
      unsigned v = 0;
      if (sscanf(s + i + 1, "%4x", &v) != 1) return false;
      if (v == 0xfffd) {
        memcpy(out + o, "\xef\xbf\xbd", 3);
        o += 3;
      } else if (v < 0x20) {
        out[o++] = (char)v;
      } else {
        return false;
      }
      i += 4;
    } else {
      return false;
    }
  }
  *outLength = o;
  return true;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  char* copy = malloc(size + 1);
  if (!copy) abort();
  memcpy(copy, data, size);
  copy[size] = '\0';
  const char* fields[FIELDS_MAX];
  int count = 0;
  for (size_t at = 0; at <= size && count < FIELDS_MAX; at += strlen(copy + at) + 1) fields[count++] = copy + at;

  // CSV: one record, read back field for field
  char* text = NULL;
  size_t textSize = 0;
  FILE* out = open_memstream(&text, &textSize);
  if (!out) abort();
  for (int k = 0; k < count; ++k) {
    if (k) fputc(',', out);
    pdu_csv_text(out, fields[k]);
  }
  fputc('\n', out);
  fclose(out);
  pduCsvCursor cursor = pdu_csv_cursor(text);
  char* back[FIELDS_MAX];
  pduCsvError error;
  // a first field that starts with a byte-order mark loses it to the cursor: no writer's field starts so
  bool bom = strncmp(fields[0], "\xef\xbb\xbf", 3) == 0 && !pdu_csv_needs_quotes(fields[0]);
  int got = pdu_csv_next(&cursor, back, NULL, FIELDS_MAX, NULL, &error);
  if (!bom) {
    if (got != count || *cursor.p != '\0') __builtin_trap();
    for (int k = 0; k < count; ++k)
      if (strcmp(back[k], fields[k]) != 0) __builtin_trap();
  }
  free(text);

  // JSON: a string that decodes to the field (valid UTF-8) and is valid UTF-8 itself
  for (int k = 0; k < count; ++k) {
    out = open_memstream(&text, &textSize);
    if (!out) abort();
    pdu_json_string(out, fields[k]);
    fclose(out);
    if (pdu_utf8_valid_length(text, textSize) != textSize) __builtin_trap();
    char* decoded = malloc(textSize + 1);
    size_t length = 0;
    if (!decoded || !json_decode(text, textSize, decoded, &length)) __builtin_trap();
    size_t n = strlen(fields[k]);
    if (pdu_utf8_valid_length(fields[k], n) == n && (length != n || memcmp(decoded, fields[k], n) != 0))
      __builtin_trap();
    free(decoded);
    free(text);
  }
  free(copy);
  return 0;
}
