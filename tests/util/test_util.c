// Tests of util/ (pdutil): every field the CSV writer writes reads back byte for byte through the record reader,
// whatever it holds (commas, quotes, CR/LF, blanks at either end, non-ASCII, tens of kilobytes); the JSON string
// writer escapes exactly what RFC 8259 asks and passes valid UTF-8 through; the file helpers.
// `test_util --fixture DIR` instead writes DIR/fields.csv and DIR/fields.json (the same random records through
// the CSV writer and the JSON writer) for the JavaScript reader's test (test_util_readers.sh).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "pdutil/csv.h"
#include "pdutil/files.h"
#include "pdutil/json.h"
#include "pdutil/utf8.h"
#include "test_random.h"

// Pieces a random field is made of: the bytes that decide quoting, blanks, and UTF-8 of 2, 3 and 4 bytes.
static const char* const pieces[] = {",", "\"", "\"\"", "\r", "\n", "\r\n", " ", "\t", "a", "Z", "0", "-", ".",
                                     ";", ":", "<", ">", "/", "=", "\\", "#", "\xc3\xa9", "\xe2\x80\x94",
                                     "\xf0\x9f\x98\x80", "\xe4\xb8\xad"};
enum { PIECES = sizeof pieces / sizeof pieces[0], RECORDS = 400, FIELDS_MAX = 12 };

// A random field (malloc'd): usually short, one in 50 over 10 000 bytes.
static char* random_field(lcg* g) {
  size_t count = lcg_uniform(g) < 0.02 ? 3000 + (size_t)(lcg_uniform(g) * 3000) : (size_t)(lcg_uniform(g) * 12);
  char* s = malloc(count * 4 + 1);
  assert_non_null(s);
  size_t n = 0;
  for (size_t k = 0; k < count; ++k) {
    const char* p = pieces[(size_t)(lcg_uniform(g) * PIECES) % PIECES];
    memcpy(s + n, p, strlen(p));
    n += strlen(p);
  }
  s[n] = '\0';
  return s;
}

typedef struct records {
  int count;
  int fields[RECORDS];
  char* text[RECORDS][FIELDS_MAX];
} records;

static records* random_records(uint64_t seed) {
  records* r = calloc(1, sizeof *r);
  assert_non_null(r);
  lcg g = {seed};
  r->count = RECORDS;
  for (int i = 0; i < RECORDS; ++i) {
    r->fields[i] = 1 + (int)(lcg_uniform(&g) * FIELDS_MAX) % FIELDS_MAX;
    for (int k = 0; k < r->fields[i]; ++k) r->text[i][k] = random_field(&g);
  }
  return r;
}

static void free_records(records* r) {
  for (int i = 0; i < r->count; ++i)
    for (int k = 0; k < r->fields[i]; ++k) free(r->text[i][k]);
  free(r);
}

static void write_csv(FILE* out, const records* r) {
  for (int i = 0; i < r->count; ++i) {
    for (int k = 0; k < r->fields[i]; ++k) {
      if (k) fputc(',', out);
      pdu_csv_text(out, r->text[i][k]);
    }
    fputc('\n', out);
  }
}

static char* csv_text(const records* r, size_t* size) {
  char* text = NULL;
  FILE* out = open_memstream(&text, size);
  assert_non_null(out);
  write_csv(out, r);
  assert_int_equal(fclose(out), 0);
  return text;
}

static void csv_round_trip(void** state) {
  (void)state;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    records* r = random_records(seed);
    size_t size;
    char* text = csv_text(r, &size);
    pduCsvCursor c = pdu_csv_cursor(text);
    char* fields[FIELDS_MAX + 1];
    pduCsvError e;
    for (int i = 0; i < r->count; ++i) {
      int n = pdu_csv_next(&c, fields, NULL, FIELDS_MAX + 1, NULL, &e);
      if (n < 0) fail_msg("seed %llu record %d: %d:%d: %s", (unsigned long long)seed, i, e.line, e.col, e.message);
      assert_int_equal(n, r->fields[i]);
      for (int k = 0; k < n; ++k) assert_string_equal(fields[k], r->text[i][k]);
    }
    assert_int_equal(pdu_csv_next(&c, fields, NULL, FIELDS_MAX + 1, NULL, &e), 0);
    free(text);
    free_records(r);
  }
}

static char* written(void (*write)(FILE*, const char*), const char* s) {
  char* text = NULL;
  size_t size;
  FILE* out = open_memstream(&text, &size);
  assert_non_null(out);
  write(out, s);
  assert_int_equal(fclose(out), 0);
  return text;
}

static void expect_written(void (*write)(FILE*, const char*), const char* s, const char* expected) {
  char* text = written(write, s);
  assert_string_equal(text, expected);
  free(text);
}

// RFC 4180 section 2, items 5-7, and the blanks spreadsheet readers trim; fields that need nothing are
// written as they are (the output files' bytes do not change for them).
static void csv_quotes_what_needs_it(void** state) {
  (void)state;
  expect_written(pdu_csv_text, "box", "box");
  expect_written(pdu_csv_text, "", "");
  expect_written(pdu_csv_text, "t\xc3\xaate", "t\xc3\xaate");
  expect_written(pdu_csv_text, "a,b", "\"a,b\"");
  expect_written(pdu_csv_text, "<img/src=x/onerror=document.title=\"PWNED\">",
                 "\"<img/src=x/onerror=document.title=\"\"PWNED\"\">\"");
  expect_written(pdu_csv_text, "two\nlines", "\"two\nlines\"");
  expect_written(pdu_csv_text, "cr\r", "\"cr\r\"");
  expect_written(pdu_csv_text, " lead", "\" lead\"");
  expect_written(pdu_csv_text, "trail\t", "\"trail\t\"");
  expect_written(pdu_csv_text, "in side", "in side");
  expect_written(pdu_csv_quoted, "scene", "\"scene\"");
}

static void csv_reader_refuses_malformed(void** state) {
  (void)state;
  const struct {
    const char* text;
    int line, col;
  } bad[] = {{"a,b\"c\n", 1, 4}, {"\"a\"b\n", 1, 4}, {"x\n\"open\nnever closed\n", 2, 1}, {"a\rb\n", 1, 2},
             {"1,2,3,4\n", 1, 7}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    char* text = strdup(bad[i].text);
    pduCsvCursor c = pdu_csv_cursor(text);
    char* fields[3];
    pduCsvError e = {0};
    int n;
    while ((n = pdu_csv_next(&c, fields, NULL, 3, NULL, &e)) > 0) {
    }
    assert_int_equal(n, -1);
    assert_int_equal(e.line, bad[i].line);
    assert_int_equal(e.col, bad[i].col);
    free(text);
  }
  // CRLF records, a byte-order mark, the line and column of each field
  char text[] = "\xef\xbb\xbfh1,h2\r\n\"multi\nline\",x\r\n";
  pduCsvCursor c = pdu_csv_cursor(text);
  char* f[2];
  int cols[2], line = 0;
  pduCsvError e;
  assert_int_equal(pdu_csv_next(&c, f, cols, 2, &line, &e), 2);
  assert_string_equal(f[1], "h2");
  assert_int_equal(line, 1);
  assert_int_equal(pdu_csv_next(&c, f, cols, 2, &line, &e), 2);
  assert_string_equal(f[0], "multi\nline");
  assert_string_equal(f[1], "x");
  assert_int_equal(line, 2);
  assert_int_equal(cols[1], 7);  // on line 3, after `line",`
  assert_int_equal(pdu_csv_next(&c, f, cols, 2, &line, &e), 0);
}

static void csv_numbers(void** state) {
  (void)state;
  char* text = NULL;
  size_t size;
  FILE* out = open_memstream(&text, &size);
  pdu_csv_number(out, 0.1, 17);
  fputc(',', out);
  pdu_csv_number(out, 1.0 / 3.0, 6);
  fputc(',', out);
  pdu_csv_number(out, 0.0 / 0.0, 6);  // not finite: an empty field
  fclose(out);
  assert_string_equal(text, "0.10000000000000001,0.333333,");
  free(text);
}

// RFC 8259 section 7: quote, backslash and U+0000..U+001F escaped; everything else as it is (valid UTF-8).
static void json_escapes(void** state) {
  (void)state;
  expect_written(pdu_json_string, "box", "\"box\"");
  expect_written(pdu_json_string, "a\"b\\c", "\"a\\\"b\\\\c\"");
  expect_written(pdu_json_string, "\x01\n\x1f", "\"\\u0001\\u000a\\u001f\"");
  expect_written(pdu_json_string, "t\xc3\xaate \xe2\x80\x94 \xf0\x9f\x98\x80 /", "\"t\xc3\xaate \xe2\x80\x94 \xf0\x9f\x98\x80 /\"");
  expect_written(pdu_json_string, "\x7f", "\"\x7f\"");
  // not UTF-8: each bad byte as U+FFFD, so the file stays valid JSON
  expect_written(pdu_json_string, "a\xff" "b", "\"a\\ufffdb\"");
  expect_written(pdu_json_string, "\xc3", "\"\\ufffd\"");
  expect_written(pdu_json_string, "\xed\xa0\x80", "\"\\ufffd\\ufffd\\ufffd\"");  // a surrogate
}

static void utf8_validation(void** state) {
  (void)state;
  assert_int_equal(pdu_utf8_valid_length("abc", 3), 3);
  assert_int_equal(pdu_utf8_valid_length("\xe2\x80\x94", 3), 3);
  assert_int_equal(pdu_utf8_valid_length("\xe2\x80\x94", 2), 0);    // cut short
  assert_int_equal(pdu_utf8_valid_length("ab\xc0\xaf", 4), 2);      // overlong '/'
  assert_int_equal(pdu_utf8_valid_length("\xf4\x90\x80\x80", 4), 0);  // above U+10FFFF
  assert_int_equal(pdu_utf8_valid_length("x\x80", 2), 1);           // stray continuation
  assert_int_equal(pdu_utf8_valid_length("\xf0\x9f\x98\x80!", 5), 5);
}

static void files(void** state) {
  (void)state;
  char root[] = "/tmp/pdutil-test-XXXXXX";
  assert_non_null(mkdtemp(root));
  char* deep = pdu_path_join(root, "a/b/c");
  assert_true(pdu_make_dirs(deep));
  assert_true(pdu_make_dirs(deep));  // existing: still true
  char* file = pdu_path_join(deep, "f.txt");
  FILE* f = fopen(file, "w");
  assert_non_null(f);
  fputs("line 1\nline 2\n", f);
  fclose(f);
  size_t size = 0;
  char* text = pdu_read_file(file, &size);
  assert_non_null(text);
  assert_int_equal(size, 14);
  assert_string_equal(text, "line 1\nline 2\n");
  free(text);
  assert_false(pdu_make_dir(file));  // a file is not a directory
  char* missing = pdu_path_suffix(file, ".missing");
  assert_null(pdu_read_file(missing, NULL));
  assert_true(pdu_remove_tree(root));
  struct stat st;
  assert_int_not_equal(stat(root, &st), 0);
  assert_true(pdu_remove_tree(root));  // already gone
  free(deep);
  free(file);
  free(missing);
}

// The fixture of the JavaScript reader's test: the same records as CSV and as a JSON array of arrays.
static int write_fixture(const char* dir) {
  records* r = random_records(20261128);
  char* path = pdu_path_join(dir, "fields.csv");
  FILE* out = fopen(path, "w");
  if (!out) return 1;
  write_csv(out, r);
  int bad = fclose(out);
  free(path);
  path = pdu_path_join(dir, "fields.json");
  out = fopen(path, "w");
  if (!out) return 1;
  fputc('[', out);
  for (int i = 0; i < r->count; ++i) {
    fputs(i ? ",\n[" : "[", out);
    for (int k = 0; k < r->fields[i]; ++k) {
      if (k) fputc(',', out);
      pdu_json_string(out, r->text[i][k]);
    }
    fputc(']', out);
  }
  fputs("]\n", out);
  bad |= fclose(out);
  free(path);
  free_records(r);
  return bad != 0;
}

int main(int argc, char** argv) {
  if (argc == 3 && strcmp(argv[1], "--fixture") == 0) return write_fixture(argv[2]);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(csv_round_trip),     cmocka_unit_test(csv_quotes_what_needs_it),
      cmocka_unit_test(csv_reader_refuses_malformed), cmocka_unit_test(csv_numbers),
      cmocka_unit_test(json_escapes),       cmocka_unit_test(utf8_validation),
      cmocka_unit_test(files),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
