// polydyn for Python — the bench: the interference oracle (refcheck/include/pdref/oracle.h), the Gedanken
// suite (gedanken/include/pdgk/gedanken.h), and the batch commands whose orchestration belongs to the command
// line (compare, cubetoss: cli/include/pdcli/commands.h), run in this process with the command's own code.
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pdcli/commands.h"
#include "pdgk/gedanken.h"
#include "pdref/oracle.h"
#include "pypolydyn.h"

// ---------------------------------------------------------------- oracle

// One checked pair of an oracle pass: which pair, when, and libccd's answer beside ours.
typedef struct oracleRow {
  long index;  // scene: sample number; random: pair number
  double t;    // scene: the sample's time, s
  int a, b;    // scene: model body indices
  pdOracleResult r;
} oracleRow;

typedef struct oracleRows {
  oracleRow* rows;
  long count, capacity;
  bool noMemory;
  pdOracleStats stats;
} oracleRows;

static bool rows_add(oracleRows* o, const oracleRow* row) {
  if (o->count == o->capacity) {
    long cap = o->capacity ? 2 * o->capacity : 256;
    oracleRow* p = realloc(o->rows, sizeof(oracleRow) * (size_t)cap);
    if (!p) {
      o->noMemory = true;
      return false;
    }
    o->rows = p;
    o->capacity = cap;
  }
  o->rows[o->count++] = *row;
  pd_oracle_stats_add(&o->stats, &row->r);
  return true;
}

static PyObject* result_tuple(const oracleRow* row) {
  const pdOracleResult* r = &row->r;
  return Py_BuildValue("(ldiisOdOOOdddOdOd)", row->index, row->t, row->a, row->b, pdOracleKindNames[r->kind],
                       r->ours ? Py_True : Py_False, r->ourDepth, r->gjk ? Py_True : Py_False,
                       r->mpr ? Py_True : Py_False, r->hasEpa ? Py_True : Py_False, r->hasEpa ? r->epaDepth : NAN,
                       r->epaBound, r->hasMprDepth ? r->mprDepth : NAN, r->touching ? Py_True : Py_False, r->scale,
                       r->stalled ? Py_True : Py_False, r->size);
}

static const char* const oracleColumns =
    "index t body_a body_b kind ours our_depth gjk mpr has_epa epa_depth epa_bound mpr_depth touching scale stalled "
    "size";

// {"columns": [...], "rows": [tuples], "kinds": {kind: count}, "failures": n, "in_band": n}
static PyObject* rows_result(oracleRows* o) {
  PyObject* list = PyList_New(o->count);
  for (long i = 0; list && i < o->count; ++i) {
    PyObject* t = result_tuple(&o->rows[i]);
    if (!t) Py_CLEAR(list);
    else PyList_SET_ITEM(list, i, t);
  }
  PyObject* kinds = PyDict_New();
  for (int k = 0; kinds && k < pd_oracleKindCount; ++k) {
    PyObject* v = PyLong_FromLong(o->stats.kinds[k]);
    if (!v || PyDict_SetItemString(kinds, pdOracleKindNames[k], v) < 0) Py_CLEAR(kinds);
    Py_XDECREF(v);
  }
  PyObject* columns = PyUnicode_FromString(oracleColumns);
  PyObject* split = columns ? PyObject_CallMethod(columns, "split", NULL) : NULL;
  PyObject* result = NULL;
  if (list && kinds && split)
    result = Py_BuildValue("{s:O,s:O,s:O,s:l,s:l,s:l}", "columns", split, "rows", list, "kinds", kinds, "failures",
                           pd_oracle_stats_failures(&o->stats), "in_band", o->stats.inBand, "pairs", o->stats.pairs);
  Py_XDECREF(columns);
  Py_XDECREF(split);
  Py_XDECREF(list);
  Py_XDECREF(kinds);
  return result;
}

static void rows_free(oracleRows* o) {
  free(o->rows);
  pd_oracle_stats_free(&o->stats);
}

// oracle_pair(spec_a, (x, y, z), (qw, qx, qy, qz), spec_b, ...): one pair of shapes written as specs.
static PyObject* oracle_pair(PyObject* module, PyObject* args) {
  (void)module;
  const char *specA, *specB;
  pdOracleBody a, b;
  if (!PyArg_ParseTuple(args, "s(ddd)(dddd)s(ddd)(dddd):oracle_pair", &specA, &a.x.x, &a.x.y, &a.x.z, &a.q.w, &a.q.x,
                        &a.q.y, &a.q.z, &specB, &b.x.x, &b.x.y, &b.x.z, &b.q.w, &b.q.x, &b.q.y, &b.q.z))
    return NULL;
  pdOracleShape shapes[2];
  char why[512];
  const char* specs[2] = {specA, specB};
  for (int i = 0; i < 2; ++i) {
    if (!pd_oracle_shape_parse(specs[i], &shapes[i], why, (int)sizeof why)) {
      if (i == 1) pd_oracle_shape_free(&shapes[0]);
      pdError err;
      pd_error_set(&err, i == 0 ? "shape a" : "shape b", 0, 0, "%s", why);
      return pd_py_raise_error(&err);
    }
  }
  double qa = a.q.w * a.q.w + a.q.x * a.q.x + a.q.y * a.q.y + a.q.z * a.q.z;
  double qb = b.q.w * b.q.w + b.q.x * b.q.x + b.q.y * b.q.y + b.q.z * b.q.z;
  if (!(qa > 0.0) || !(qb > 0.0) || !isfinite(qa) || !isfinite(qb)) {
    pd_oracle_shape_free(&shapes[0]);
    pd_oracle_shape_free(&shapes[1]);
    return PyErr_Format(PyExc_ValueError, "a quaternion must be finite and not zero");
  }
  a.q = pd_quat_normalize(a.q);
  b.q = pd_quat_normalize(b.q);
  a.shape = &shapes[0].poly;
  b.shape = &shapes[1].poly;
  oracleRows o = {0};
  pd_oracle_stats_init(&o.stats);
  oracleRow row = {.a = 0, .b = 1};
  Py_BEGIN_ALLOW_THREADS
  pd_oracle_check(&a, &b, &row.r);
  Py_END_ALLOW_THREADS
  rows_add(&o, &row);
  pd_oracle_shape_free(&shapes[0]);
  pd_oracle_shape_free(&shapes[1]);
  PyObject* result = o.noMemory ? PyErr_NoMemory() : rows_result(&o);
  rows_free(&o);
  return result;
}

typedef struct sceneCheck {
  oracleRows rows;
  long sample;
} sceneCheck;

// Every pair of bodies that are not both fixed (the engine never tests those either), at every sample.
static bool oracle_observe(const pdModel* model, const pdState* state, void* user) {
  sceneCheck* c = user;
  for (int i = 0; i < model->bodyCount; ++i) {
    for (int j = i + 1; j < model->bodyCount; ++j) {
      if (model->bodies[i].fixed && model->bodies[j].fixed) continue;
      pdBodyState pi = pd_state_body(model, state, i), pj = pd_state_body(model, state, j);
      pdOracleBody a = {&model->bodies[i].shape, pi.x, pi.q}, b = {&model->bodies[j].shape, pj.x, pj.q};
      oracleRow row = {.index = c->sample, .t = state->t, .a = i, .b = j};
      pd_oracle_check(&a, &b, &row.r);
      if (!rows_add(&c->rows, &row)) return false;
    }
  }
  ++c->sample;
  return !pdPyInterrupted;
}

static PyObject* oracle_scene(PyObject* module, PyObject* args) {
  (void)module;
  PyObject* modelObject;
  int catchInterrupt = 0;
  if (!PyArg_ParseTuple(args, "O!p:oracle_scene", &pdPyModelType, &modelObject, &catchInterrupt)) return NULL;
  const pdModel* model = ((pdPyModel*)modelObject)->model;
  sceneCheck c = {0};
  pd_oracle_stats_init(&c.rows.stats);
  pdPyInterruptScope scope;
  pd_py_interrupt_begin(&scope, catchInterrupt);
  Py_BEGIN_ALLOW_THREADS
  pdState* state = pd_state_create(model, NULL);
  pd_advance(model, state, model->settings.tend, oracle_observe, &c);
  pd_state_free(state);
  Py_END_ALLOW_THREADS
  pd_py_interrupt_end(&scope);
  PyObject* result = NULL;
  if (scope.caught && pdPyInterrupted) PyErr_SetNone(PyExc_KeyboardInterrupt);
  else if (c.rows.noMemory) PyErr_NoMemory();
  else result = rows_result(&c.rows);
  rows_free(&c.rows);
  return result;
}

static PyObject* oracle_random(PyObject* module, PyObject* args) {
  (void)module;
  long n;
  unsigned long long seed;
  int catchInterrupt = 0;
  if (!PyArg_ParseTuple(args, "lKp:oracle_random", &n, &seed, &catchInterrupt)) return NULL;
  if (n < 1) return PyErr_Format(PyExc_ValueError, "n must be >= 1");
  oracleRows o = {0};
  pd_oracle_stats_init(&o.stats);
  pdPyInterruptScope scope;
  pd_py_interrupt_begin(&scope, catchInterrupt);
  Py_BEGIN_ALLOW_THREADS
  pdOracleRng g;
  pd_oracle_rng_seed(&g, seed);
  for (long i = 0; i < n && !pdPyInterrupted && !o.noMemory; ++i) {
    pdOraclePair p;
    pd_oracle_random_pair(&g, &p);
    oracleRow row = {.index = i, .a = 0, .b = 1};
    pd_oracle_check(&p.bodyA, &p.bodyB, &row.r);
    rows_add(&o, &row);
    pd_oracle_pair_free(&p);
  }
  Py_END_ALLOW_THREADS
  pd_py_interrupt_end(&scope);
  PyObject* result = NULL;
  if (scope.caught && pdPyInterrupted) PyErr_SetNone(PyExc_KeyboardInterrupt);
  else if (o.noMemory) PyErr_NoMemory();
  else result = rows_result(&o);
  rows_free(&o);
  return result;
}

// ---------------------------------------------------------------- the Gedanken suite

// A list of str as a NULL-terminated array of UTF-8 pointers into the list's strings (kept alive by the list).
static const char** string_array(PyObject* list, int* count) {
  Py_ssize_t n = PyList_Size(list);
  if (n < 0) return NULL;
  const char** a = calloc((size_t)n + 1, sizeof(char*));
  if (!a) return (const char**)PyErr_NoMemory();
  for (Py_ssize_t i = 0; i < n; ++i) {
    a[i] = PyUnicode_AsUTF8(PyList_GET_ITEM(list, i));
    if (!a[i]) {
      free(a);
      return NULL;
    }
  }
  *count = (int)n;
  return a;
}

static PyObject* gedanken(PyObject* module, PyObject* args, PyObject* kwargs) {
  (void)module;
  static char* names[] = {"out", "only", "engines", "fast", "jobs", "precision", "repeats", "catch_interrupt", NULL};
  PyObject *outObject, *only = Py_None, *engines;
  int fast = 0, jobs = 1, precision = 0, repeats = 1, catchInterrupt = 0;
  if (!PyArg_ParseTupleAndKeywords(args, kwargs, "O&OO!|pipip:gedanken", names, PyUnicode_FSConverter, &outObject,
                                   &only, &PyList_Type, &engines, &fast, &jobs, &precision, &repeats, &catchInterrupt))
    return NULL;
  pdGkOptions o = {.out = PyBytes_AS_STRING(outObject), .fast = fast, .jobs = jobs, .toleranceScale = 1.0,
                   .precision = precision, .repeats = repeats, .interrupt = &pdPyInterrupted};
  PyObject* result = NULL;
  const char** onlyNames = NULL;
  int engineCount = 0;
  const char** engineNames = string_array(engines, &engineCount);
  if (!engineNames) goto done;
  for (int i = 0; i < engineCount; ++i) {
    pdGkEngine e;
    if (!pd_gk_engine_named(engineNames[i], &e)) {
      PyErr_Format(PyExc_ValueError, "engines must be among soft, ode, bullet, not '%s'", engineNames[i]);
      goto done;
    }
    o.engines[e] = true;
  }
  if (only != Py_None) {
    if (!PyList_Check(only)) {
      PyErr_SetString(PyExc_TypeError, "only must be a list of experiment names or None");
      goto done;
    }
    if (!(onlyNames = string_array(only, &o.onlyCount))) goto done;
    for (int i = 0; i < o.onlyCount; ++i)
      if (!pd_gk_find(onlyNames[i])) {
        PyErr_Format(PyExc_ValueError, "no Gedanken experiment is called '%s'", onlyNames[i]);
        goto done;
      }
    o.only = onlyNames;
  }
  if (jobs < 1 || jobs > 64 || repeats < 1) {
    PyErr_SetString(PyExc_ValueError, "jobs must be 1..64 and repeats >= 1");
    goto done;
  }
  if (pd_gk_selected_count(&o) == 0) {
    PyErr_SetString(PyExc_ValueError, "no experiment selected");
    goto done;
  }
  pdError err = {0};
  if (!pd_gk_out_replaceable(o.out, &err)) {
    pd_py_raise_error(&err);
    goto done;
  }
  pdGkSummary summary = {0};
  pdPyInterruptScope scope;
  pd_py_interrupt_begin(&scope, catchInterrupt);
  bool ok;
  Py_BEGIN_ALLOW_THREADS
  ok = pd_gk_run_suite(&o, &summary, &err);
  Py_END_ALLOW_THREADS
  pd_py_interrupt_end(&scope);
  if (summary.interrupted || (scope.caught && pdPyInterrupted)) PyErr_SetNone(PyExc_KeyboardInterrupt);
  else if (!ok) PyErr_Format(PyExc_OSError, "%s: %s", err.file, err.message);
  else
    result = Py_BuildValue("{s:i,s:i,s:s,s:d}", "rows", summary.rows, "soft_failures", summary.softFailures,
                           "soft_failed", summary.softFailed, "wall_seconds", summary.wallSeconds);
done:
  free(engineNames);
  free(onlyNames);
  Py_DECREF(outObject);
  return result;
}

static PyObject* gedanken_experiments(PyObject* module, PyObject* noArgs) {
  (void)module, (void)noArgs;
  int n = pd_gk_experiment_count();
  PyObject* list = PyList_New(n);
  for (int i = 0; list && i < n; ++i) {
    const pdGkExperiment* e = pd_gk_experiment(i);
    PyObject* d = Py_BuildValue("{s:s,s:c,s:s,s:s,s:s,s:s,s:O,s:O}", "name", e->name, "group", e->group, "title",
                                e->title, "quantity", e->quantity, "unit", e->unit, "kind", pdGkKindNames[e->kind],
                                "qualitative", e->qualitative ? Py_True : Py_False, "fast",
                                e->fast ? Py_True : Py_False);
    if (!d) Py_CLEAR(list);
    else PyList_SET_ITEM(list, i, d);
  }
  return list;
}

// ---------------------------------------------------------------- the batch commands

// `polydyn compare ...` or `polydyn cubetoss ...` in this process: the command's own code reads, runs and writes
// its directory; the caller reads the files back. The command catches SIGINT and SIGTERM itself
// (pd_cli_catch_interrupts); Python's handlers are put back afterwards. Returns the exit status.
static PyObject* command(PyObject* module, PyObject* args) {
  (void)module;
  PyObject* list;
  if (!PyArg_ParseTuple(args, "O!:command", &PyList_Type, &list)) return NULL;
  int argc = 0;
  const char** argv = string_array(list, &argc);
  if (!argv) return NULL;
  int (*fn)(int, char**) = NULL;
  if (argc >= 1 && strcmp(argv[0], "compare") == 0) fn = pd_cmd_compare;
  else if (argc >= 1 && strcmp(argv[0], "cubetoss") == 0) fn = pd_cmd_cubetoss;
  if (!fn) {
    free(argv);
    return PyErr_Format(PyExc_ValueError, "command runs compare or cubetoss");
  }
  struct sigaction previousInt, previousTerm;
  sigaction(SIGINT, NULL, &previousInt);
  sigaction(SIGTERM, NULL, &previousTerm);
  int status;
  Py_BEGIN_ALLOW_THREADS
  pd_cli_interrupted = 0;
  status = fn(argc, (char**)argv);
  fflush(stdout);
  fflush(stderr);
  Py_END_ALLOW_THREADS
  sigaction(SIGINT, &previousInt, NULL);
  sigaction(SIGTERM, &previousTerm, NULL);
  free(argv);
  return PyLong_FromLong(status);
}

PyMethodDef pdPyBenchFunctions[] = {
    {"oracle_pair", oracle_pair, METH_VARARGS, "oracle_pair(spec_a, x_a, q_a, spec_b, x_b, q_b): one pair checked"},
    {"oracle_scene", oracle_scene, METH_VARARGS, "oracle_scene(model, catch_interrupt): every pair at every sample"},
    {"oracle_random", oracle_random, METH_VARARGS, "oracle_random(n, seed, catch_interrupt): random pairs"},
    {"gedanken", (PyCFunction)(void (*)(void))gedanken, METH_VARARGS | METH_KEYWORDS,
     "gedanken(out, only, engines, ...): pd_gk_run_suite into out"},
    {"gedanken_experiments", gedanken_experiments, METH_NOARGS, "the catalogue: one dict per experiment"},
    {"command", command, METH_VARARGS, "command([name, args...]): polydyn compare or cubetoss in this process"},
    {NULL, NULL, 0, NULL},
};
