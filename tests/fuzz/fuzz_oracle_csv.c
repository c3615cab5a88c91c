// libFuzzer target for the oracle's replay CSV (refcheck/oracle_csv.c: pd_oracle_replay_buffer, as
// `polydyn oracle --replay` reads a file): any bytes must give either rows that replay — each pair is checked
// again by our SAT and libccd, as the command does, and the row it would write reads back the same — or one
// well-formed error.
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_checks.h"
#include "pdref/oracle.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static bool unit(pdQuat q) { return fabs(sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z) - 1.0) <= 1e-9; }

static bool same_text(const char* a, const char* b) { return a && b && strcmp(a, b) == 0; }

// The pair checked again, and its row written and read back as the next replay of that output would.
static bool visit(const pdOracleRow* listed, const pdOracleShape* sa, const pdOracleShape* sb, long line, void* user) {
  long* rows = user;
  if (line < 2 || !listed->source || !listed->nameA || !listed->nameB || !unit(listed->qa) || !unit(listed->qb) ||
      (unsigned)listed->r.kind >= pd_oracleKindCount || sa->poly.vertexCount < 4 || sb->poly.vertexCount < 4)
    __builtin_trap();
  pdOracleRow row = *listed;
  pdOracleBody a = {&sa->poly, row.xa, row.qa}, b = {&sb->poly, row.xb, row.qb};
  pd_oracle_check(&a, &b, &row.r);
  if ((unsigned)row.r.kind >= pd_oracleKindCount) __builtin_trap();

  char* text = NULL;
  size_t textSize = 0;
  FILE* out = open_memstream(&text, &textSize);
  if (!out) abort();
  pd_oracle_csv_write(out, &row);
  fclose(out);
  text[strcspn(text, "\n")] = '\0';
  pdOracleRow back;
  int col = 0;
  char why[PD_ERROR_MESSAGE_MAX];
  if (!pd_oracle_csv_read(text, &back, &col, why, sizeof why)) __builtin_trap();  // a row it cannot replay
  if (!same_text(back.source, row.source) || !same_text(back.nameA, row.nameA) || !same_text(back.nameB, row.nameB) ||
      !same_text(back.specA, row.specA) || !same_text(back.specB, row.specB) || back.r.kind != row.r.kind ||
      back.index != row.index || memcmp(&back.xa, &row.xa, sizeof row.xa) != 0 ||
      memcmp(&back.qb, &row.qb, sizeof row.qb) != 0)
    __builtin_trap();
  free(text);
  ++*rows;
  return true;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pdError err;
  long rows = 0;
  if (!pd_oracle_replay_buffer("fuzz.csv", (const char*)data, size, visit, &rows, &err)) fuzz_check_error(&err, 1);
  return 0;
}
