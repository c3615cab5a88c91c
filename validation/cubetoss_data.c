// polydyn validation — reading the cube-toss CSV, the train/test split and toss lists (cubetoss.h).
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pdutil/csv.h"
#include "pdval/cubetoss.h"

#define TOSS_HEADER "toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz"
#define DROP_HEADER "drop,t,x,z,th,vx,vz,vth"
enum { TOSS_FIELDS = 15, DROP_FIELDS = 8 };

const pdTossExperiment pd_cube_tosses = {.name = "cube tosses",
                                         .header = TOSS_HEADER,
                                         .rate = PD_TOSS_RATE,
                                         .size = {PD_TOSS_CUBE_SIDE, PD_TOSS_CUBE_SIDE, PD_TOSS_CUBE_SIDE},
                                         .side = PD_TOSS_CUBE_SIDE,
                                         .mass = PD_TOSS_CUBE_MASS,
                                         .boardTop = PD_TOSS_BOARD_TOP,
                                         .vmax = PD_TOSS_VMAX,
                                         .planar = false,
                                         .lengthUnit = "cube_widths"};
const pdTossExperiment pd_planar_drops = {.name = "planar drops",
                                          .header = DROP_HEADER,
                                          .rate = PD_DROP_RATE,
                                          .size = {PD_DROP_SIDE, PD_DROP_SIDE, PD_DROP_SIDE},
                                          .side = PD_DROP_SIDE,
                                          .mass = PD_DROP_MASS,
                                          .boardTop = PD_DROP_BOARD_TOP,
                                          .vmax = PD_DROP_VMAX,
                                          .planar = true,
                                          .lengthUnit = "side_lengths"};

static void* grow(void* p, size_t count, size_t size) {
  void* q = realloc(p, count * size);
  if (!q) abort();
  return q;
}

void pd_toss_set_free(pdTossSet* set) {
  if (!set) return;
  for (int i = 0; i < set->count; ++i) free(set->tosses[i].samples);
  free(set->tosses);
  free(set->path);
  free(set);
}

static bool parse_number(const char* text, double* v) {
  char* end = NULL;
  errno = 0;
  *v = strtod(text, &end);
  return end != text && *end == '\0' && errno != ERANGE && isfinite(*v);
}

static bool parse_id(const char* text, long* v) {
  char* end = NULL;
  errno = 0;
  *v = strtol(text, &end, 10);
  return end != text && *end == '\0' && errno != ERANGE;
}

// The lines of a file (getline) or of a caller's buffer (each copied out in turn), so that pd_toss_read and
// pd_toss_parse_buffer run the same code on the same bytes. A line keeps its '\n' and any NUL bytes.
typedef struct lineSource {
  FILE* file;        // NULL: the buffer
  const char* data;
  size_t size, at;
  char* line;        // the current line (owned, NUL-terminated)
  size_t capacity;
} lineSource;

// The next line's length in bytes (as getline), or -1 at the end (or on a read error of the file).
static ssize_t next_line(lineSource* s) {
  if (s->file) return getline(&s->line, &s->capacity, s->file);
  if (s->at >= s->size) return -1;
  const char* start = s->data + s->at;
  const char* newline = memchr(start, '\n', s->size - s->at);
  size_t len = newline ? (size_t)(newline - start) + 1 : s->size - s->at;
  if (len + 1 > s->capacity) {
    s->capacity = len + 1;
    s->line = grow(s->line, s->capacity, 1);
  }
  memcpy(s->line, start, len);
  s->line[len] = '\0';
  s->at += len;
  return (ssize_t)len;
}

static pdTossSet* parse(const char* path, lineSource* src, pdError* err) {
  pdTossSet* set = calloc(1, sizeof *set);
  if (!set) abort();
  set->path = strdup(path);
  if (!set->path) abort();
  int capacity = 0, sampleCapacity = 0;
  long lineNo = 0;
  bool ok = true;
  pdToss* cur = NULL;
  for (ssize_t len; ok && (len = next_line(src)) >= 0;) {
    char* line = src->line;
    ++lineNo;
    while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r')) line[--len] = '\0';
    if ((size_t)len != strlen(line)) {
      pd_error_set(err, path, (int)lineNo, (int)strlen(line) + 1, "not text (a NUL byte)");
      ok = false;
      break;
    }
    if (lineNo == 1) {
      if (strcmp(line, TOSS_HEADER) == 0) {
        set->experiment = &pd_cube_tosses;
      } else if (strcmp(line, DROP_HEADER) == 0) {
        set->experiment = &pd_planar_drops;
      } else {
        pd_error_set(err, path, 1, 1, "header is not `" TOSS_HEADER "` (cube tosses) nor `" DROP_HEADER "` (planar drops)");
        ok = false;
      }
      continue;
    }
    if (len == 0) continue;  // a blank line (e.g. at the end) carries nothing
    const pdTossExperiment* ex = set->experiment;
    const int fieldCount = ex->planar ? DROP_FIELDS : TOSS_FIELDS;
    // one line, one record (RFC 4180, pdutil/csv.h); room to count a few fields too many
    char* fields[4 * TOSS_FIELDS];
    int cols[4 * TOSS_FIELDS];
    pduCsvCursor cursor = pdu_csv_cursor(line);
    pduCsvError bad;
    int n = pdu_csv_next(&cursor, fields, cols, 4 * TOSS_FIELDS, NULL, &bad);
    if (n < 0) {
      pd_error_set(err, path, (int)lineNo, bad.col, "%s", bad.message);
      ok = false;
      break;
    }
    if (n != fieldCount) {
      pd_error_set(err, path, (int)lineNo, 1, "%d fields, expected %d (%s)", n, fieldCount, ex->header);
      ok = false;
      break;
    }
    long id;
    if (!parse_id(fields[0], &id)) {
      pd_error_set(err, path, (int)lineNo, cols[0], "toss: not an integer: '%.40s'", fields[0]);
      ok = false;
      break;
    }
    double v[TOSS_FIELDS - 1];
    for (int f = 1; f < fieldCount && ok; ++f) {
      if (!parse_number(fields[f], &v[f - 1])) {
        pd_error_set(err, path, (int)lineNo, cols[f], "not a finite number: '%.40s'", fields[f]);
        ok = false;
      }
    }
    if (!ok) break;
    // a new toss starts where the id changes; its id must not have been seen before
    if (!cur || cur->id != id) {
      for (int i = 0; i < set->count; ++i)
        if (set->tosses[i].id == id) {
          pd_error_set(err, path, (int)lineNo, cols[0], "toss %ld continues after other tosses (line %ld): its rows must be consecutive",
                       id, set->tosses[i].line);
          ok = false;
        }
      if (cur && cur->sampleCount < 2) {
        pd_error_set(err, path, (int)cur->line, 1, "toss %ld has one row: a toss needs at least 2", cur->id);
        ok = false;
      }
      if (!ok) break;
      if (set->count == capacity) {
        capacity = capacity ? 2 * capacity : 64;
        set->tosses = grow(set->tosses, (size_t)capacity, sizeof *set->tosses);
      }
      cur = &set->tosses[set->count++];
      *cur = (pdToss){.experiment = ex, .id = id, .line = lineNo};
      sampleCapacity = 0;
    }
    int k = cur->sampleCount;
    double expected = (double)k / ex->rate;
    if (fabs(v[0] - expected) > PD_TOSS_TIME_TOL) {
      pd_error_set(err, path, (int)lineNo, cols[1], "t = %.9g s, expected %.9g s (sample %d of %s %ld at %g Hz)", v[0],
                   expected, k, ex->planar ? "drop" : "toss", id, ex->rate);
      ok = false;
      break;
    }
    pdBodyState b;
    if (ex->planar) {
      // (x, z, th) in the x–z plane: th turns x towards z, a rotation about −y (cubetoss.h)
      b = (pdBodyState){.x = {v[1], 0.0, v[2]},
                        .q = {cos(0.5 * v[3]), 0.0, -sin(0.5 * v[3]), 0.0},
                        .v = {v[4], 0.0, v[5]},
                        .w = {0.0, -v[6], 0.0}};
    } else {
      pdQuat q = {v[4], v[5], v[6], v[7]};
      double norm = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
      if (fabs(norm - 1.0) > PD_TOSS_QUAT_NORM_TOL) {
        pd_error_set(err, path, (int)lineNo, cols[5], "quaternion norm %.9g, expected 1", norm);
        ok = false;
        break;
      }
      b = (pdBodyState){.x = {v[1], v[2], v[3]},
                        .q = {q.w / norm, q.x / norm, q.y / norm, q.z / norm},
                        .v = {v[8], v[9], v[10]},
                        .w = {v[11], v[12], v[13]}};
    }
    if (k == sampleCapacity) {
      sampleCapacity = sampleCapacity ? 2 * sampleCapacity : 128;
      cur->samples = grow(cur->samples, (size_t)sampleCapacity, sizeof *cur->samples);
    }
    cur->samples[k] = b;
    ++cur->sampleCount;
  }
  if (ok && src->file && ferror(src->file)) {
    pd_error_set(err, path, 0, 0, "read error");
    ok = false;
  }
  if (ok && lineNo == 0) {
    pd_error_set(err, path, 0, 0, "empty file (expected the header `" TOSS_HEADER "` or `" DROP_HEADER "`)");
    ok = false;
  }
  if (ok && set->count == 0) {
    pd_error_set(err, path, 2, 1, "no tosses after the header");
    ok = false;
  }
  if (ok && cur && cur->sampleCount < 2) {
    pd_error_set(err, path, (int)cur->line, 1, "toss %ld has one row: a toss needs at least 2", cur->id);
    ok = false;
  }
  if (!ok) {
    pd_toss_set_free(set);
    return NULL;
  }
  return set;
}

pdTossSet* pd_toss_read(const char* path, pdError* err) {
  FILE* in = fopen(path, "r");
  if (!in) {
    pd_error_set(err, path, 0, 0, "cannot read: %s", strerror(errno));
    return NULL;
  }
  lineSource src = {.file = in};
  pdTossSet* set = parse(path, &src, err);
  free(src.line);
  fclose(in);
  return set;
}

pdTossSet* pd_toss_parse_buffer(const char* name, const char* data, size_t size, pdError* err) {
  PD_ASSERT(data != NULL || size == 0);
  lineSource src = {.data = data, .size = size};
  pdTossSet* set = parse(name ? name : "<buffer>", &src, err);
  free(src.line);
  return set;
}

pdTossSplit pd_toss_split(int index) {
  PD_ASSERT(index >= 0);
  return index % 2 == 0 ? pd_tossTrain : pd_tossTest;
}

const char* pd_toss_split_name(pdTossSplit split) { return split == pd_tossTrain ? "train" : "test"; }

bool pd_toss_select(const pdTossSet* set, const char* list, int** indices, int* count, char* why, size_t whySize) {
  PD_ASSERT(set && list && indices && count);
  bool* chosen = calloc((size_t)set->count, sizeof *chosen);
  if (!chosen) abort();
  bool ok = true;
  if (strcmp(list, "all") == 0 || strcmp(list, "train") == 0 || strcmp(list, "test") == 0) {
    for (int i = 0; i < set->count; ++i)
      chosen[i] = list[0] == 'a' || (list[1] == 'r') == (pd_toss_split(i) == pd_tossTrain);
  } else if (!list[0]) {
    snprintf(why, whySize, "empty toss list");
    ok = false;
  } else {
    for (const char* p = list; ok && p;) {
      const char* comma = strchr(p, ',');
      size_t len = comma ? (size_t)(comma - p) : strlen(p);
      char word[64];
      if (len == 0 || len >= sizeof word) {
        snprintf(why, whySize, "bad toss list entry '%.*s'", (int)(len < 40 ? len : 40), p);
        ok = false;
        break;
      }
      memcpy(word, p, len);
      word[len] = '\0';
      // an id, or a range FIRST-LAST of ids (ids are non-negative in the data)
      long first, last;
      char* dash = strchr(word + 1, '-');
      if (dash) *dash = '\0';
      if (!parse_id(word, &first) || (dash && !parse_id(dash + 1, &last))) {
        if (dash) *dash = '-';
        snprintf(why, whySize, "bad toss list entry '%s' (expected an id or a range FIRST-LAST)", word);
        ok = false;
        break;
      }
      if (!dash) last = first;
      if (last < first) {
        snprintf(why, whySize, "empty toss range %ld-%ld", first, last);
        ok = false;
        break;
      }
      // a single id must be in the data; a range must hold at least one (ids need not be contiguous)
      int hits = 0;
      for (int i = 0; i < set->count; ++i)
        if (set->tosses[i].id >= first && set->tosses[i].id <= last) chosen[i] = true, ++hits;
      if (hits == 0) {
        if (dash)
          snprintf(why, whySize, "no toss of %s has an id in %ld-%ld", set->path, first, last);
        else
          snprintf(why, whySize, "toss %ld is not in %s", first, set->path);
        ok = false;
        break;
      }
      p = comma ? comma + 1 : NULL;
    }
  }
  int n = 0;
  for (int i = 0; i < set->count; ++i) n += chosen[i];
  if (ok && n == 0) {
    snprintf(why, whySize, "no toss selected by '%s'", list);
    ok = false;
  }
  *indices = NULL;
  *count = 0;
  if (ok) {
    *indices = malloc((size_t)n * sizeof **indices);
    if (!*indices) abort();
    for (int i = 0; i < set->count; ++i)
      if (chosen[i]) (*indices)[(*count)++] = i;
  }
  free(chosen);
  return ok;
}
