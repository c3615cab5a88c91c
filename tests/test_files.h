// polydyn tests — a whole file read into memory, for comparing outputs byte for byte. Include after <cmocka.h>.
#pragma once

#include <stdio.h>
#include <stdlib.h>

// The bytes of `path` with a '\0' after them (the caller frees); *size their count. Fails the test when the file
// cannot be read.
static inline char* test_read_file(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  if (!f) fail_msg("cannot open %s", path);
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char* data = malloc((size_t)n + 1);
  assert_non_null(data);
  assert_int_equal(fread(data, 1, (size_t)n, f), (size_t)n);
  data[n] = '\0';
  fclose(f);
  *size = (size_t)n;
  return data;
}
