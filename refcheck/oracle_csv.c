// polydyn refcheck — the oracle's disagreement CSV: one row per listed pair, enough to replay it
// (pdref/oracle.h). RFC 4180 quoting for the text fields (scene body names may hold commas).
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pdutil/csv.h"
#include "pdref/oracle.h"

// A quaternion read back must be unit to this (|q| − 1): %.17g round-trips exactly, so only a
// hand-edited file can miss it; a non-unit q would scale the body.
#define UNIT_QUAT_TOL 1e-9

static const char* const header =
    "source,index,t,kind,name_a,name_b,shape_a,shape_b,"
    "ax,ay,az,aqw,aqx,aqy,aqz,bx,by,bz,bqw,bqx,bqy,bqz,"
    "our_verdict,our_depth,gjk_verdict,mpr_verdict,epa_depth,mpr_depth,scale,size,epa_tol\n";

void pd_oracle_csv_header(FILE* out) { fputs(header, out); }

static void put_number(FILE* out, double v) { fprintf(out, ",%.17g", v); }

// an empty field for a value libccd did not give (never a NaN)
static void put_optional(FILE* out, bool has, double v) {
  if (has)
    put_number(out, v);
  else
    fputc(',', out);
}

static const char* verdict(bool overlap) { return overlap ? "overlap" : "separate"; }

void pd_oracle_csv_write(FILE* out, const pdOracleRow* row) {
  const pdOracleResult* r = &row->r;
  pdu_csv_text(out, row->source);
  fprintf(out, ",%ld,%.17g,%s,", row->index, row->t, pdOracleKindNames[r->kind]);
  const char* texts[4] = {row->nameA, row->nameB, row->specA, row->specB};
  for (int i = 0; i < 4; ++i) {
    pdu_csv_text(out, texts[i]);
    fputc(',', out);
  }
  const double pose[14] = {row->xa.x, row->xa.y, row->xa.z, row->qa.w, row->qa.x, row->qa.y, row->qa.z,
                           row->xb.x, row->xb.y, row->xb.z, row->qb.w, row->qb.x, row->qb.y, row->qb.z};
  fprintf(out, "%.17g", pose[0]);
  for (int i = 1; i < 14; ++i) put_number(out, pose[i]);
  fprintf(out, ",%s", verdict(r->ours));
  put_number(out, r->ourDepth);
  fprintf(out, ",%s,%s", verdict(r->gjk), verdict(r->mpr));
  put_optional(out, r->hasEpa, r->epaDepth);
  put_optional(out, r->hasMprDepth, r->mprDepth);
  put_number(out, r->scale);
  put_number(out, r->size);
  put_optional(out, r->hasEpa, r->epaTol);
  fputc('\n', out);
}

static bool read_number(const char* s, double* v) {
  char* end = NULL;
  errno = 0;
  *v = strtod(s, &end);
  return end != s && *end == '\0' && errno != ERANGE && isfinite(*v);
}

static bool read_verdict(const char* s, bool* overlap) {
  if (strcmp(s, "overlap") == 0) return (*overlap = true);
  if (strcmp(s, "separate") == 0) return !(*overlap = false);
  return false;
}

static bool fail(int* col, int at, char* why, int whySize, const char* message, const char* field) {
  *col = at;
  snprintf(why, (size_t)whySize, "%s: '%.60s'", message, field);
  return false;
}

bool pd_oracle_csv_read(char* buf, pdOracleRow* row, int* col, char* why, int whySize) {
  PD_ASSERT(buf != NULL && row != NULL && col != NULL);
  memset(row, 0, sizeof *row);
  char* f[PD_ORACLE_CSV_FIELDS + 1];
  int at[PD_ORACLE_CSV_FIELDS + 1];
  pduCsvCursor cursor = pdu_csv_cursor(buf);
  pduCsvError bad;
  int n = pdu_csv_next(&cursor, f, at, PD_ORACLE_CSV_FIELDS + 1, NULL, &bad);
  if (n < 0) {
    *col = bad.col;
    snprintf(why, (size_t)whySize, "%s", bad.message);
    return false;
  }
  if (*cursor.p != '\0') {  // one line is one record: a line break inside a field does not belong here
    *col = (int)(cursor.p - buf) + 1;
    snprintf(why, (size_t)whySize, "a record must fit on one line");
    return false;
  }
  if (n != PD_ORACLE_CSV_FIELDS) {
    *col = 1;
    snprintf(why, (size_t)whySize, "%d fields, expected %d", n, PD_ORACLE_CSV_FIELDS);
    return false;
  }
  row->source = f[0];
  double v[14];
  if (!read_number(f[1], &v[0]) || v[0] < 0 || v[0] != floor(v[0]) || v[0] > 9e15)
    return fail(col, at[1], why, whySize, "index is not a whole number >= 0", f[1]);
  row->index = (long)v[0];
  if (!read_number(f[2], &row->t)) return fail(col, at[2], why, whySize, "t is not a finite number", f[2]);
  int kind = 0;
  while (kind < pd_oracleKindCount && strcmp(f[3], pdOracleKindNames[kind]) != 0) ++kind;
  if (kind == pd_oracleKindCount) return fail(col, at[3], why, whySize, "unknown kind", f[3]);
  row->r.kind = (pdOracleKind)kind;
  row->nameA = f[4];
  row->nameB = f[5];
  row->specA = f[6];
  row->specB = f[7];
  for (int i = 0; i < 14; ++i)
    if (!read_number(f[8 + i], &v[i])) return fail(col, at[8 + i], why, whySize, "pose value is not a finite number", f[8 + i]);
  row->xa = (pdVec3){v[0], v[1], v[2]};
  row->qa = (pdQuat){v[3], v[4], v[5], v[6]};
  row->xb = (pdVec3){v[7], v[8], v[9]};
  row->qb = (pdQuat){v[10], v[11], v[12], v[13]};
  const pdQuat* q[2] = {&row->qa, &row->qb};
  for (int k = 0; k < 2; ++k) {
    double norm = sqrt(q[k]->w * q[k]->w + q[k]->x * q[k]->x + q[k]->y * q[k]->y + q[k]->z * q[k]->z);
    if (!(fabs(norm - 1.0) <= UNIT_QUAT_TOL))
      return fail(col, at[11 + 7 * k], why, whySize, "quaternion is not unit", f[11 + 7 * k]);
  }
  // what the file says was found (the replay computes its own)
  pdOracleResult* r = &row->r;
  if (!read_verdict(f[22], &r->ours)) return fail(col, at[22], why, whySize, "verdict is not overlap or separate", f[22]);
  if (!read_number(f[23], &r->ourDepth)) return fail(col, at[23], why, whySize, "not a finite number", f[23]);
  if (!read_verdict(f[24], &r->gjk)) return fail(col, at[24], why, whySize, "verdict is not overlap or separate", f[24]);
  if (!read_verdict(f[25], &r->mpr)) return fail(col, at[25], why, whySize, "verdict is not overlap or separate", f[25]);
  r->hasEpa = f[26][0] != '\0';
  if (r->hasEpa && !read_number(f[26], &r->epaDepth)) return fail(col, at[26], why, whySize, "not a finite number", f[26]);
  r->hasMprDepth = f[27][0] != '\0';
  if (r->hasMprDepth && !read_number(f[27], &r->mprDepth))
    return fail(col, at[27], why, whySize, "not a finite number", f[27]);
  if (!read_number(f[28], &r->scale)) return fail(col, at[28], why, whySize, "not a finite number", f[28]);
  if (!read_number(f[29], &r->size)) return fail(col, at[29], why, whySize, "not a finite number", f[29]);
  if (r->hasEpa != (f[30][0] != '\0') || (r->hasEpa && !read_number(f[30], &r->epaTol)))
    return fail(col, at[30], why, whySize, "not a finite number, or given without epa_depth", f[30]);
  return true;
}

// ---------------------------------------------------------------- replaying a whole file

// A shape kept across rows: consecutive rows usually list the same bodies.
typedef struct cachedShape {
  pdOracleShape s;
  bool valid;
} cachedShape;

static bool cached_shape(cachedShape* c, const char* spec, char* why, int whySize) {
  if (c->valid && strcmp(c->s.spec, spec) == 0) return true;
  if (c->valid) pd_oracle_shape_free(&c->s);
  c->valid = pd_oracle_shape_parse(spec, &c->s, why, whySize);
  return c->valid;
}

bool pd_oracle_replay_buffer(const char* name, const char* data, size_t size, pdOracleReplayFcn* visit, void* user,
                             pdError* err) {
  PD_ASSERT(data != NULL || size == 0);
  if (!name) name = "<buffer>";
  cachedShape shapes[2];
  memset(shapes, 0, sizeof shapes);
  char* line = NULL;  // the current line, split in place by pd_oracle_csv_read
  size_t capacity = 0;
  bool ok = true, going = true;
  long lineNo = 0;
  for (size_t at = 0; ok && going && (at < size || lineNo == 0);) {
    ++lineNo;
    const char* start = data ? data + at : "";
    const char* newline = size > at ? memchr(start, '\n', size - at) : NULL;
    size_t len = newline ? (size_t)(newline - start) : size - at;
    at += newline ? len + 1 : len;
    if (len > 0 && start[len - 1] == '\r') --len;
    if (len + 1 > capacity) {
      capacity = len + 1;
      if (!(line = realloc(line, capacity))) abort();
    }
    memcpy(line, start, len);
    line[len] = '\0';
    if (strlen(line) != len) {
      pd_error_set(err, name, (int)lineNo, (int)strlen(line) + 1, "not a text line (NUL byte)");
      ok = false;
    } else if (lineNo == 1) {
      if (strlen(header) - 1 != len || strncmp(line, header, len) != 0) {
        pd_error_set(err, name, 1, 1, "not an oracle CSV (the header differs from the one 'polydyn oracle' writes)");
        ok = false;
      }
    } else if (len > 0) {
      pdOracleRow row;
      int col = 1;
      char why[PD_ERROR_MESSAGE_MAX];
      if (!pd_oracle_csv_read(line, &row, &col, why, sizeof why)) {
        pd_error_set(err, name, (int)lineNo, col, "%s", why);
        ok = false;
        break;
      }
      const char* specs[2] = {row.specA, row.specB};
      for (int k = 0; k < 2 && ok; ++k) {
        if (!cached_shape(&shapes[k], specs[k], why, sizeof why)) {
          // the field starts where its (unquoted) text starts in the split line
          pd_error_set(err, name, (int)lineNo, (int)(specs[k] - line) + 1, "shape_%c: %s", 'a' + k, why);
          ok = false;
        }
      }
      if (ok && visit) going = visit(&row, &shapes[0].s, &shapes[1].s, lineNo, user);
    }
  }
  for (int k = 0; k < 2; ++k)
    if (shapes[k].valid) pd_oracle_shape_free(&shapes[k].s);
  free(line);
  return ok;
}
