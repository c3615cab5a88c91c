// polydyn viewer — reading a run directory: summary.json (cJSON), trajectory.csv, contacts.csv.
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pdutil/csv.h"
#include "pdutil/files.h"
#include "view_internal.h"

static const char* const trajectoryHeader = "t,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz";
static const char* const contactsHeader = "t,body_a,body_b,kind,feat_a,feat_b,px,py,pz,nx,ny,nz,fn,ftx,fty,ftz,mode";

static void* xmalloc(size_t n) {
  void* p = malloc(n ? n : 1);
  PD_ASSERT(p != NULL);
  return p;
}

static void* xrealloc(void* p, size_t n) {
  p = realloc(p, n ? n : 1);
  PD_ASSERT(p != NULL);
  return p;
}

static char* xstrdup(const char* s) {
  size_t n = strlen(s) + 1;
  return memcpy(xmalloc(n), s, n);
}

// ---------------------------------------------------------------- CSV

// A CSV file read line by line (a record of trajectory.csv or contacts.csv never spans lines: body names
// hold no line break, docs/names-and-files.md), each line split by the shared RFC 4180 reader (pdutil/csv.h).
enum { CSV_FIELDS_MAX = 18 };  // contacts.csv's 17, and one to tell "more"
typedef struct csvReader {
  FILE* in;
  const char* path;
  char* line;        // current line, without its line break, split in place
  size_t lineCap;
  size_t lineLength;
  int lineNo;
  char* fields[CSV_FIELDS_MAX];
  int cols[CSV_FIELDS_MAX];
  int count;         // fields of the current line
  int next;          // index of the next field csv_field returns
  int col;           // column of the field last returned
} csvReader;

// Reads and splits the next line: 1, 0 at the end of the file, -1 (err filled) for a malformed line.
static int csv_next_line(csvReader* r, pdError* err) {
  ssize_t n = getline(&r->line, &r->lineCap, r->in);
  if (n < 0) return 0;
  while (n > 0 && (r->line[n - 1] == '\n' || r->line[n - 1] == '\r')) r->line[--n] = '\0';
  r->lineLength = (size_t)n;
  r->lineNo++;
  pduCsvCursor cursor = pdu_csv_cursor(r->line);
  pduCsvError bad;
  r->count = n == 0 ? 0 : pdu_csv_next(&cursor, r->fields, r->cols, CSV_FIELDS_MAX, NULL, &bad);
  r->next = 0;
  if (r->count < 0) {
    pd_error_set(err, r->path, r->lineNo, bad.col, "%s", bad.message);
    return -1;
  }
  return 1;
}

// Next field of the line; NULL when the line has no more fields.
static const char* csv_field(csvReader* r) {
  if (r->next >= r->count) return NULL;
  r->col = r->cols[r->next];
  return r->fields[r->next++];
}

// Whether the line has fields left.
static bool csv_more(const csvReader* r) { return r->next < r->count; }

static bool csv_number(csvReader* r, const char* field, double* value, pdError* err) {
  char* end = NULL;
  errno = 0;
  double v = strtod(field, &end);
  if (end == field || *end != '\0' || !isfinite(v)) {
    pd_error_set(err, r->path, r->lineNo, r->col, "not a finite number: '%.40s'", field);
    return false;
  }
  *value = v;
  return true;
}

// Reads `count` number fields that follow `before` fields of a row of `total` fields.
static bool csv_numbers(csvReader* r, double* out, int count, int before, int total, pdError* err) {
  for (int c = 0; c < count; ++c) {
    const char* field = csv_field(r);
    if (!field) {
      pd_error_set(err, r->path, r->lineNo, (int)r->lineLength + 1, "expected %d fields, found %d", total, before + c);
      return false;
    }
    if (!csv_number(r, field, &out[c], err)) return false;
  }
  return true;
}

// Opens a CSV file and checks its header line.
static bool csv_open(csvReader* r, const char* path, const char* header, pdError* err) {
  memset(r, 0, sizeof *r);
  r->path = path;
  r->in = fopen(path, "r");
  if (!r->in) {
    pd_error_set(err, path, 0, 0, "cannot read: %s", strerror(errno));
    return false;
  }
  char* expected = strdup(header);
  if (!expected) abort();
  bool same = csv_next_line(r, err) > 0;
  // the header's names, field by field
  for (char *name = expected, *end = NULL; same && name; name = end ? end + 1 : NULL) {
    end = strchr(name, ',');
    if (end) *end = '\0';
    const char* field = csv_field(r);
    same = field && strcmp(field, name) == 0;
  }
  same = same && !csv_more(r);
  free(expected);
  if (!same) {
    pd_error_set(err, path, 1, 1, "expected the header '%s'", header);
    return false;
  }
  return true;
}

static void csv_close(csvReader* r) {
  if (r->in) fclose(r->in);
  free(r->line);
}

// ---------------------------------------------------------------- summary.json

static const cJSON* member(const cJSON* obj, const char* name) { return cJSON_GetObjectItemCaseSensitive(obj, name); }

static bool numbers(const cJSON* array, double* out, int count) {
  if (!cJSON_IsArray(array) || cJSON_GetArraySize(array) != count) return false;
  int i = 0;
  const cJSON* x;
  cJSON_ArrayForEach(x, array) {
    if (!cJSON_IsNumber(x)) return false;
    out[i++] = x->valuedouble;
  }
  return true;
}

// summary.json writes q as [w, [x, y, z]]; [w, x, y, z] is accepted too
static bool quaternion(const cJSON* q, double out[4]) {
  if (numbers(q, out, 4)) return true;
  if (!cJSON_IsArray(q) || cJSON_GetArraySize(q) != 2) return false;
  const cJSON* w = cJSON_GetArrayItem(q, 0);
  if (!cJSON_IsNumber(w)) return false;
  out[0] = w->valuedouble;
  return numbers(cJSON_GetArrayItem(q, 1), out + 1, 3);
}

static cJSON* number_array(const double* x, int count) { return cJSON_CreateDoubleArray(x, count); }

// Checks one body of summary.json and adds what the page needs to `bodies`.
static bool read_body(const cJSON* b, int index, const char* path, cJSON* bodies, pdViewRun* run, pdError* err) {
  const cJSON* name = member(b, "name");
  const cJSON* color = member(b, "color");
  const cJSON* fixed = member(b, "fixed");
  const cJSON* mass = member(b, "mass");
  const cJSON* size = member(b, "size");
  const cJSON* initial = member(b, "initial");
  const cJSON* shape = member(b, "shape");
  double inertia[9], x[3], q[4];
  const cJSON* rows = member(b, "inertia");
  bool inertiaOk = cJSON_IsArray(rows) && cJSON_GetArraySize(rows) == 3;
  for (int i = 0; inertiaOk && i < 3; ++i) inertiaOk = numbers(cJSON_GetArrayItem(rows, i), inertia + 3 * i, 3);
  if (!cJSON_IsString(name) || !cJSON_IsString(color) || !cJSON_IsBool(fixed) || !cJSON_IsNumber(mass) ||
      !cJSON_IsNumber(size) || !inertiaOk || !numbers(member(initial, "x"), x, 3) ||
      !quaternion(member(initial, "q"), q) || !cJSON_IsObject(shape)) {
    pd_error_set(err, path, 0, 0, "body %d: needs name, color, fixed, mass, size, inertia, initial x and q, shape",
                 index);
    return false;
  }
  run->names[index] = xstrdup(name->valuestring);
  run->fixed[index] = cJSON_IsTrue(fixed);

  // the polyhedron: vertices in the body frame, faces as vertex lists (counter-clockwise from outside)
  const cJSON* vertices = member(shape, "vertices");
  const cJSON* faces = member(shape, "faces");
  int vertexCount = cJSON_GetArraySize(vertices);
  if (!cJSON_IsArray(vertices) || vertexCount < 4 || !cJSON_IsArray(faces) || cJSON_GetArraySize(faces) < 4) {
    pd_error_set(err, path, 0, 0, "body '%s': shape needs at least 4 vertices and 4 faces", name->valuestring);
    return false;
  }
  cJSON* flatVertices = cJSON_CreateArray();
  const cJSON* v;
  cJSON_ArrayForEach(v, vertices) {
    double p[3];
    if (!numbers(v, p, 3)) {
      cJSON_Delete(flatVertices);
      pd_error_set(err, path, 0, 0, "body '%s': a vertex is not 3 numbers", name->valuestring);
      return false;
    }
    for (int k = 0; k < 3; ++k) cJSON_AddItemToArray(flatVertices, cJSON_CreateNumber(p[k]));
  }
  const cJSON* f;
  cJSON_ArrayForEach(f, faces) {
    const cJSON* i;
    bool ok = cJSON_IsArray(f) && cJSON_GetArraySize(f) >= 3;
    cJSON_ArrayForEach(i, f) ok = ok && cJSON_IsNumber(i) && i->valueint >= 0 && i->valueint < vertexCount;
    if (!ok) {
      cJSON_Delete(flatVertices);
      pd_error_set(err, path, 0, 0, "body '%s': a face is not 3 or more vertex indices", name->valuestring);
      return false;
    }
  }
  cJSON* out = cJSON_CreateObject();
  cJSON_AddStringToObject(out, "name", name->valuestring);
  cJSON_AddStringToObject(out, "color", color->valuestring);
  cJSON_AddBoolToObject(out, "fixed", run->fixed[index]);
  cJSON_AddNumberToObject(out, "mass", mass->valuedouble);
  cJSON_AddNumberToObject(out, "size", size->valuedouble);
  cJSON_AddItemToObject(out, "inertia", number_array(inertia, 9));
  cJSON_AddItemToObject(out, "x", number_array(x, 3));
  cJSON_AddItemToObject(out, "q", number_array(q, 4));
  cJSON_AddItemToObject(out, "vertices", flatVertices);
  cJSON_AddItemToObject(out, "faces", cJSON_Duplicate(faces, true));
  cJSON_AddItemToArray(bodies, out);
  return true;
}

// Reads summary.json: fills names, fixed, the moving order, and the page's JSON (without the layout).
static cJSON* read_summary(pdViewRun* run, pdError* err) {
  char* path = pdu_path_join(run->dir, "summary.json");
  char* text = pdu_read_file(path, NULL);
  if (!text) pd_error_set(err, path, 0, 0, "cannot read: %s", strerror(errno));
  cJSON* summary = text ? cJSON_ParseWithOpts(text, NULL, true) : NULL;
  cJSON* meta = NULL;
  if (text && !summary) {
    // cJSON reports where it stopped; turn that into a line and column
    const char* at = cJSON_GetErrorPtr();
    int line = 1, col = 1;
    for (const char* p = text; at && p < at; ++p) {
      if (*p == '\n') line++, col = 1;
      else col++;
    }
    pd_error_set(err, path, line, col, "not valid JSON");
  }
  free(text);
  if (!summary) goto done;

  const cJSON* engine = member(summary, "engine");
  const cJSON* scene = member(summary, "scene");
  const cJSON* settings = member(summary, "settings");
  const cJSON* bodies = member(summary, "bodies");
  double gravity[3];
  if (!cJSON_IsString(engine) || !cJSON_IsString(scene) || !numbers(member(settings, "gravity"), gravity, 3) ||
      !cJSON_IsArray(bodies) || cJSON_GetArraySize(bodies) < 1) {
    pd_error_set(err, path, 0, 0, "not a polydyn run summary (needs engine, scene, settings.gravity, bodies)");
    goto done;
  }
  run->bodyCount = cJSON_GetArraySize(bodies);
  run->names = calloc((size_t)run->bodyCount, sizeof *run->names);
  run->fixed = calloc((size_t)run->bodyCount, sizeof *run->fixed);
  PD_ASSERT(run->names && run->fixed);
  meta = cJSON_CreateObject();
  cJSON_AddStringToObject(meta, "engine", engine->valuestring);
  cJSON_AddStringToObject(meta, "scene", scene->valuestring);
  cJSON_AddStringToObject(meta, "dir", run->dir);
  cJSON_AddItemToObject(meta, "gravity", number_array(gravity, 3));
  const cJSON* completed = member(summary, "completed");
  cJSON_AddBoolToObject(meta, "completed", !cJSON_IsBool(completed) || cJSON_IsTrue(completed));
  cJSON* outBodies = cJSON_AddArrayToObject(meta, "bodies");
  int index = 0;
  const cJSON* b;
  cJSON_ArrayForEach(b, bodies) {
    if (!read_body(b, index, path, outBodies, run, err)) {
      cJSON_Delete(meta);
      meta = NULL;
      goto done;
    }
    for (int j = 0; j < index; ++j)
      if (strcmp(run->names[j], run->names[index]) == 0) {
        pd_error_set(err, path, 0, 0, "two bodies named '%s'", run->names[index]);
        cJSON_Delete(meta);
        meta = NULL;
        goto done;
      }
    index++;
  }
  run->moving = xmalloc((size_t)run->bodyCount * sizeof *run->moving);
  for (int i = 0; i < run->bodyCount; ++i)
    if (!run->fixed[i]) run->moving[run->movingCount++] = i;
done:
  cJSON_Delete(summary);
  free(path);
  return meta;
}

// ---------------------------------------------------------------- trajectory.csv

static bool read_trajectory(pdViewRun* run, pdError* err) {
  char* path = pdu_path_join(run->dir, "trajectory.csv");
  csvReader r;
  bool ok = csv_open(&r, path, trajectoryHeader, err);
  int m = run->movingCount;
  size_t cap = 0;
  int row = 0;  // row within the current sample
  int got = 0;
  while (ok && (got = csv_next_line(&r, err)) > 0) {
    double t;
    const char* field = csv_field(&r);
    if (!field || !csv_number(&r, field, &t, err)) {
      if (!field) pd_error_set(err, path, r.lineNo, 1, "expected 15 fields");
      ok = false;
      break;
    }
    if (row == 0) {
      if (run->sampleCount > 0 && !(t > run->t[run->sampleCount - 1])) {
        pd_error_set(err, path, r.lineNo, r.col, "time %.17g does not increase", t);
        ok = false;
        break;
      }
      if ((size_t)run->sampleCount == cap) {
        cap = cap ? 2 * cap : 1024;
        run->t = xrealloc(run->t, cap * sizeof *run->t);
        run->pose = xrealloc(run->pose, cap * (size_t)m * PD_VIEW_POSE * sizeof *run->pose);
        run->vel = xrealloc(run->vel, cap * (size_t)m * PD_VIEW_VEL * sizeof *run->vel);
      }
      run->t[run->sampleCount++] = t;
    } else if (t != run->t[run->sampleCount - 1]) {
      pd_error_set(err, path, r.lineNo, r.col, "sample at t = %.17g has %d of its %d moving bodies",
                   run->t[run->sampleCount - 1], row, m);
      ok = false;
      break;
    }
    const char* expected = run->names[run->moving[row]];
    field = csv_field(&r);
    if (!field || strcmp(field, expected) != 0) {
      pd_error_set(err, path, r.lineNo, field ? r.col : 1, "expected body '%s' (moving bodies in scene order)",
                   expected);
      ok = false;
      break;
    }
    size_t base = (size_t)(run->sampleCount - 1) * (size_t)m + (size_t)row;
    double values[13];
    ok = csv_numbers(&r, values, 13, 2, 15, err);
    if (ok && csv_more(&r)) {
      pd_error_set(err, path, r.lineNo, r.cols[r.next], "more than 15 fields");
      ok = false;
    }
    if (!ok) break;
    memcpy(run->pose + base * PD_VIEW_POSE, values, PD_VIEW_POSE * sizeof(double));
    for (int c = 0; c < PD_VIEW_VEL; ++c) run->vel[base * PD_VIEW_VEL + (size_t)c] = (float)values[PD_VIEW_POSE + c];
    row = (row + 1) % m;
  }
  if (got < 0) ok = false;
  if (ok && ferror(r.in)) {
    pd_error_set(err, path, r.lineNo, 0, "read error");
    ok = false;
  }
  if (ok && row != 0) {
    pd_error_set(err, path, r.lineNo, 1, "the last sample has %d of its %d moving bodies", row, m);
    ok = false;
  }
  if (ok && run->sampleCount == 0) {
    pd_error_set(err, path, r.lineNo, 1, "no samples");
    ok = false;
  }
  csv_close(&r);
  free(path);
  return ok;
}

// ---------------------------------------------------------------- contacts.csv

typedef struct nameIndex {
  const char* name;
  int index;
} nameIndex;

static int compare_names(const void* a, const void* b) {
  return strcmp(((const nameIndex*)a)->name, ((const nameIndex*)b)->name);
}

static bool body_field(csvReader* r, const nameIndex* sorted, int count, int* index, pdError* err) {
  const char* field = csv_field(r);
  if (!field) {
    pd_error_set(err, r->path, r->lineNo, (int)r->lineLength + 1, "expected 17 fields");
    return false;
  }
  nameIndex key = {field, 0};
  const nameIndex* hit = bsearch(&key, sorted, (size_t)count, sizeof *sorted, compare_names);
  if (!hit) {
    pd_error_set(err, r->path, r->lineNo, r->col, "no body named '%.60s' in summary.json", field);
    return false;
  }
  *index = hit->index;
  return true;
}

static bool read_contacts(pdViewRun* run, pdError* err) {
  run->contactStart = calloc((size_t)run->sampleCount + 1, sizeof *run->contactStart);
  PD_ASSERT(run->contactStart != NULL);
  char* path = pdu_path_join(run->dir, "contacts.csv");
  FILE* probe = fopen(path, "r");
  if (!probe && errno == ENOENT) {  // reference engines may write none
    free(path);
    return true;
  }
  if (probe) fclose(probe);
  run->hasContacts = true;
  nameIndex* sorted = xmalloc((size_t)run->bodyCount * sizeof *sorted);
  for (int i = 0; i < run->bodyCount; ++i) sorted[i] = (nameIndex){run->names[i], i};
  qsort(sorted, (size_t)run->bodyCount, sizeof *sorted, compare_names);

  csvReader r;
  bool ok = csv_open(&r, path, contactsHeader, err);
  size_t cap = 0;
  int sample = 0;
  int got = 0;
  while (ok && (got = csv_next_line(&r, err)) > 0) {
    double t;
    const char* field = csv_field(&r);
    if (!field) {
      pd_error_set(err, path, r.lineNo, 1, "expected 17 fields");
      ok = false;
      break;
    }
    if (!csv_number(&r, field, &t, err)) {
      ok = false;
      break;
    }
    while (sample < run->sampleCount && run->t[sample] < t) run->contactStart[++sample] = (uint32_t)run->contactCount;
    if (sample == run->sampleCount || run->t[sample] != t) {
      pd_error_set(err, path, r.lineNo, r.col, "time %.17g is not a trajectory sample (or goes back)", t);
      ok = false;
      break;
    }
    int a, b;
    ok = body_field(&r, sorted, run->bodyCount, &a, err) && body_field(&r, sorted, run->bodyCount, &b, err);
    if (!ok) break;
    field = csv_field(&r);
    int flags = 0;
    if (field && strcmp(field, "EE") == 0)
      flags |= PD_VIEW_EDGE_EDGE;
    else if (!field || strcmp(field, "VF") != 0) {
      pd_error_set(err, path, r.lineNo, field ? r.col : 1, "kind must be VF or EE");
      ok = false;
      break;
    }
    double v[12];  // feat_a, feat_b, p, n, fn, ft
    if (!(ok = csv_numbers(&r, v, 12, 4, 17, err))) break;
    field = csv_field(&r);
    if (field && strcmp(field, "slip") == 0)
      flags |= PD_VIEW_SLIP;
    else if (!field || strcmp(field, "stick") != 0) {
      pd_error_set(err, path, r.lineNo, field ? r.col : 1, "mode must be stick or slip");
      ok = false;
      break;
    }
    if ((size_t)run->contactCount == cap) {
      cap = cap ? 2 * cap : 1024;
      run->contactFloat = xrealloc(run->contactFloat, cap * PD_VIEW_CFLOAT * sizeof *run->contactFloat);
      run->contactInt = xrealloc(run->contactInt, cap * PD_VIEW_CINT * sizeof *run->contactInt);
    }
    float* cf = run->contactFloat + (size_t)run->contactCount * PD_VIEW_CFLOAT;
    // force on body_a: fn along n plus the tangential force
    const double* p = v + 2;
    const double* n = v + 5;
    double fn = v[8];
    for (int k = 0; k < 3; ++k) {
      cf[k] = (float)p[k];
      cf[3 + k] = (float)(fn * n[k] + v[9 + k]);
    }
    int32_t* ci = run->contactInt + (size_t)run->contactCount * PD_VIEW_CINT;
    ci[0] = a;
    ci[1] = b;
    ci[2] = flags;
    run->contactCount++;
  }
  if (got < 0) ok = false;
  while (ok && sample < run->sampleCount) run->contactStart[++sample] = (uint32_t)run->contactCount;
  csv_close(&r);
  free(sorted);
  free(path);
  return ok;
}

// ---------------------------------------------------------------- the run

static size_t align8(size_t n) { return (n + 7) & ~(size_t)7; }

pdViewLayout pd_view_layout(const pdViewRun* run) {
  size_t s = (size_t)run->sampleCount, m = (size_t)run->movingCount, c = (size_t)run->contactCount;
  pdViewLayout l = {.bytes = {s * sizeof(double), s * m * PD_VIEW_POSE * sizeof(double), s * m * PD_VIEW_VEL * sizeof(float),
                              (s + 1) * sizeof(uint32_t), c * PD_VIEW_CFLOAT * sizeof(float),
                              c * PD_VIEW_CINT * sizeof(int32_t)}};
  for (int i = 0; i < PD_VIEW_BLOCKS; ++i) {
    l.offset[i] = l.total;
    l.total += align8(l.bytes[i]);
  }
  return l;
}

pdViewRun* pd_view_run_load(const char* dir, pdError* err) {
  pdViewRun* run = calloc(1, sizeof *run);
  PD_ASSERT(run != NULL);
  run->dir = xstrdup(dir);
  cJSON* meta = read_summary(run, err);
  if (!meta || !read_trajectory(run, err) || !read_contacts(run, err)) {
    cJSON_Delete(meta);
    pd_view_run_free(run);
    return NULL;
  }
  cJSON_AddNumberToObject(meta, "samples", run->sampleCount);
  cJSON_AddItemToObject(meta, "moving", cJSON_CreateIntArray(run->moving, run->movingCount));
  cJSON_AddNumberToObject(meta, "contacts", run->contactCount);
  cJSON_AddBoolToObject(meta, "hasContacts", run->hasContacts);
  pdViewLayout l = pd_view_layout(run);
  static const char* const names[PD_VIEW_BLOCKS] = {"t", "pose", "vel", "contactStart", "contactFloat", "contactInt"};
  cJSON* layout = cJSON_AddObjectToObject(meta, "layout");
  for (int i = 0; i < PD_VIEW_BLOCKS; ++i) {
    double ob[2] = {(double)l.offset[i], (double)l.bytes[i]};
    cJSON_AddItemToObject(layout, names[i], number_array(ob, 2));
  }
  cJSON_AddNumberToObject(meta, "bytes", (double)l.total);
  run->metaJson = cJSON_PrintUnformatted(meta);
  PD_ASSERT(run->metaJson != NULL);
  cJSON_Delete(meta);
  return run;
}

void pd_view_run_free(pdViewRun* run) {
  if (!run) return;
  for (int i = 0; run->names && i < run->bodyCount; ++i) free(run->names[i]);
  free(run->names);
  free(run->fixed);
  free(run->moving);
  free(run->t);
  free(run->pose);
  free(run->vel);
  free(run->contactStart);
  free(run->contactFloat);
  free(run->contactInt);
  cJSON_free(run->metaJson);
  free(run->dir);
  free(run);
}

double pd_view_run_t_first(const pdViewRun* run) { return run->t[0]; }
double pd_view_run_t_last(const pdViewRun* run) { return run->t[run->sampleCount - 1]; }

bool pd_view_runs_compatible(const pdViewRun* a, const pdViewRun* b, pdError* err) {
  if (a->bodyCount != b->bodyCount) {
    pd_error_set(err, b->dir, 0, 0, "not the same scene as %s: %d bodies, not %d", a->dir, b->bodyCount, a->bodyCount);
    return false;
  }
  for (int i = 0; i < a->bodyCount; ++i)
    if (strcmp(a->names[i], b->names[i]) != 0 || a->fixed[i] != b->fixed[i]) {
      pd_error_set(err, b->dir, 0, 0, "not the same scene as %s: body %d is '%s'%s there, '%s'%s here", a->dir, i + 1,
                   a->names[i], a->fixed[i] ? " (fixed)" : "", b->names[i], b->fixed[i] ? " (fixed)" : "");
      return false;
    }
  return true;
}
