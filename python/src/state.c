// polydyn for Python — State (polydyn/state.h) and run(): a whole run recorded into arrays, in the soft engine
// or a reference engine, with an optional Python callback at every output sample.
//
// Recording: the observer appends each sample to growing blocks (t; per moving body x, q, v, w; every active
// contact as one pdPyContact) with the GIL released; at the end each block is handed to a Buffer that NumPy
// views, so no sample is copied twice. A callback takes the GIL for its call only and sees the run's state
// through a borrowed State, valid during the call.
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "polydyn/output.h"
#include "pdref/refcheck.h"
#include "pypolydyn.h"

// One contact of one sample (contacts.csv's columns, with the sample's index and the contact's depth).
typedef struct pdPyContact {
  double t;             // s
  int64_t sample;       // index k of the sample, t = k / sample rate
  int32_t bodyA, bodyB; // model body indices; A carries the vertex (VF) or the first edge (EE)
  int32_t featureA, featureB;
  double point[3];      // m, world
  double normal[3];     // unit, from B into A
  double depth;         // m, > 0 overlapping
  double fn;            // N, normal force on A
  double ft[3];         // N, friction force on A
  uint8_t edgeEdge;     // 0 VF, 1 EE
  uint8_t slip;         // 0 stick, 1 slip
  uint8_t pad[6];
} pdPyContact;

enum { POSE_DOUBLES = 13 };  // x (3), q (4, w first), v (3), w (3)
// A recorded row: t (double), the body's model index (int64), its pose: trajectory.csv's row, so NumPy views the
// whole recording as one structured array and x, q, v, w as strided views of it.
enum { ROW_SLOTS = 2 + POSE_DOUBLES };

static void pose_write(double* out, pdBodyState b) {
  double v[POSE_DOUBLES] = {b.x.x, b.x.y, b.x.z, b.q.w, b.q.x, b.q.y, b.q.z, b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z};
  memcpy(out, v, sizeof v);
}

static void contact_write(pdPyContact* c, const pdState* state, int j, long sample) {
  pdContactReport r = pd_state_contact(state, j);
  *c = (pdPyContact){.t = state->t, .sample = sample, .bodyA = r.bodyA, .bodyB = r.bodyB, .featureA = r.featureA,
                     .featureB = r.featureB, .point = {r.point.x, r.point.y, r.point.z},
                     .normal = {r.normal.x, r.normal.y, r.normal.z}, .depth = r.depth, .fn = r.fn,
                     .ft = {r.ft.x, r.ft.y, r.ft.z}, .edgeEdge = r.edgeEdge, .slip = r.slip};
}

// ---------------------------------------------------------------- interrupts

volatile sig_atomic_t pdPyInterrupted = 0;
unsigned long pdPyMainThread = 0;

static void on_interrupt(int sig) {
  (void)sig;
  pdPyInterrupted = 1;
}

void pd_py_interrupt_begin(pdPyInterruptScope* scope, bool catchSignal) {
  scope->caught = catchSignal;
  if (!catchSignal) return;
  pdPyInterrupted = 0;
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_interrupt;
  sigaction(SIGINT, &sa, &scope->previous);
}

void pd_py_interrupt_end(pdPyInterruptScope* scope) {
  if (scope->caught) sigaction(SIGINT, &scope->previous, NULL);
}

// ---------------------------------------------------------------- the observer

typedef struct recorder {
  bool record;           // keep the samples (run) or only call back (State.advance)
  bool recordContacts;
  int moving;
  long samples, capacity;
  double* t;             // (capacity)
  double* poses;         // (capacity × moving × ROW_SLOTS) rows, sample-major
  long contacts, contactCapacity;
  pdPyContact* contact;  // (contactCapacity)
  bool noMemory;
  pdRunWriter* writer;   // nullable: also write the run directory (soft engine)
  bool writeFailed;
  PyObject* callback;    // nullable
  pdPyState* view;       // the borrowed State the callback sees
  PyThreadState* thread; // saved while the GIL is released
  bool callbackFailed;   // it raised (the exception stays set)
  bool callbackStopped;  // it returned False
} recorder;

static bool grow(void** p, long* capacity, long need, size_t itemSize) {
  if (need <= *capacity) return true;
  long cap = *capacity > 0 ? *capacity : 64;
  while (cap < need) cap *= 2;
  void* q = realloc(*p, (size_t)cap * itemSize);
  if (!q) return false;
  *p = q;
  *capacity = cap;
  return true;
}

static bool record_sample(recorder* r, const pdModel* model, const pdState* state) {
  long k = r->samples;
  if (k + 1 > r->capacity) {
    long cap = r->capacity;
    if (!grow((void**)&r->t, &cap, k + 1, sizeof(double))) return false;
    long poseCap = r->capacity;
    if (!grow((void**)&r->poses, &poseCap, k + 1, sizeof(double) * ROW_SLOTS * (size_t)(r->moving > 0 ? r->moving : 1)))
      return false;
    r->capacity = cap < poseCap ? cap : poseCap;
  }
  r->t[k] = state->t;
  for (int j = 0; j < r->moving; ++j) {
    double* row = &r->poses[((size_t)k * (size_t)r->moving + (size_t)j) * ROW_SLOTS];
    int64_t body = model->movingBodies[j];
    row[0] = state->t;
    memcpy(&row[1], &body, sizeof body);
    pose_write(&row[2], pd_state_body(model, state, model->movingBodies[j]));
  }
  if (r->recordContacts) {
    int n = pd_state_contact_count(state);
    if (!grow((void**)&r->contact, &r->contactCapacity, r->contacts + n, sizeof(pdPyContact))) return false;
    for (int j = 0; j < n; ++j) contact_write(&r->contact[r->contacts + j], state, j, k);
    r->contacts += n;
  }
  r->samples = k + 1;
  return true;
}

static bool observe(const pdModel* model, const pdState* state, void* user) {
  recorder* r = user;
  if (r->writer && !pd_run_observe(model, state, r->writer)) {
    r->writeFailed = true;
    return false;
  }
  if (r->record && !record_sample(r, model, state)) {
    r->noMemory = true;
    return false;
  }
  if (r->callback) {
    PyEval_RestoreThread(r->thread);
    r->view->state = (pdState*)state;  // read-only to the callback: the borrowed State has no mutating method
    PyObject* result = PyObject_CallOneArg(r->callback, (PyObject*)r->view);
    if (!result)
      r->callbackFailed = true;
    else if (result == Py_False)
      r->callbackStopped = true;
    Py_XDECREF(result);
    r->thread = PyEval_SaveThread();
  }
  return !pdPyInterrupted && !r->callbackFailed && !r->callbackStopped;
}

static void recorder_free(recorder* r) {
  free(r->t);
  free(r->poses);
  free(r->contact);
}

// ---------------------------------------------------------------- State

static pdPyState* state_alloc(PyObject* modelObject, const pdModel* model, pdState* state, bool borrowed) {
  pdPyState* s = PyObject_New(pdPyState, &pdPyStateType);
  if (!s) return NULL;
  Py_XINCREF(modelObject);
  s->modelObject = modelObject;
  s->model = model;
  s->state = state;
  s->borrowed = borrowed;
  return s;
}

static bool parse_stepper(const char* name, pdStepper* out) {
  static const struct { const char* name; pdStepper stepper; } steppers[] = {
      {"implicit", pd_stepperImplicit}, {"adaptive", pd_stepperRK4Adaptive},
      {"fixed", pd_stepperRK4Fixed},    {"embedded", pd_stepperRK43Embedded},
      {"dopri", pd_stepperDopri54},     {"implicit-dopri", pd_stepperImplicitDopri}};
  for (size_t i = 0; i < sizeof steppers / sizeof steppers[0]; ++i)
    if (strcmp(name, steppers[i].name) == 0) {
      *out = steppers[i].stepper;
      return true;
    }
  PyErr_Format(PyExc_ValueError, "stepper must be implicit, adaptive, fixed, embedded, dopri or implicit-dopri, not '%s'", name);
  return false;
}

static bool parse_onsets(const char* name, pdOnsets* out) {
  if (strcmp(name, "auto") == 0) *out = pd_onsetsAuto;
  else if (strcmp(name, "pair") == 0) *out = pd_onsetsPair;
  else if (strcmp(name, "exact") == 0) *out = pd_onsetsExact;
  else if (strcmp(name, "bounded") == 0) *out = pd_onsetsBounded;
  else {
    PyErr_Format(PyExc_ValueError, "onsets must be bounded, pair, exact or auto, not '%s'", name);
    return false;
  }
  return true;
}

static bool parse_islands(const char* name, pdIslands* out) {
  if (strcmp(name, "on") == 0) *out = pd_islandsOn;
  else if (strcmp(name, "off") == 0) *out = pd_islandsOff;
  else {
    PyErr_Format(PyExc_ValueError, "islands must be on or off, not '%s'", name);
    return false;
  }
  return true;
}

// The soft engine's options, checked as `polydyn run` checks them.
typedef struct softOptions {
  pdStepper stepper;
  pdOnsets onsets;
  pdIslands islands;
  int threads;
} softOptions;

static bool soft_options(const char* stepper, const char* onsets, const char* islands, int threads, softOptions* o) {
  o->stepper = PD_STEPPER_DEFAULT;
  o->onsets = PD_ONSETS_DEFAULT;
  o->islands = PD_ISLANDS_DEFAULT;
  o->threads = threads;
  if (stepper && !parse_stepper(stepper, &o->stepper)) return false;
  if (onsets && !parse_onsets(onsets, &o->onsets)) return false;
  if (islands && !parse_islands(islands, &o->islands)) return false;
  if (threads < 1 || threads > PD_THREADS_MAX) {
    PyErr_Format(PyExc_ValueError, "threads must be a whole number 1..%d", PD_THREADS_MAX);
    return false;
  }
  // islands off is one system on one thread: more threads would be silently idle
  if (threads > 1 && o->islands != pd_islandsOn) {
    PyErr_SetString(PyExc_ValueError, "threads > 1 needs islands='on'");
    return false;
  }
  return true;
}

static pdState* soft_state_create(const pdModel* model, const softOptions* o) {
  pdStateOptions options = pd_state_options_default();
  options.stepper = o->stepper;
  options.onsets = o->onsets;
  options.islands = o->islands;
  options.threads = o->threads;
  return pd_state_create(model, &options);
}

static PyObject* state_new(PyTypeObject* type, PyObject* args, PyObject* kwargs) {
  (void)type;
  static char* names[] = {"model", "stepper", "onsets", "islands", "threads", NULL};
  PyObject* modelObject;
  const char *stepper = NULL, *onsets = NULL, *islands = NULL;
  int threads = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kwargs, "O!|$zzzi:State", names, &pdPyModelType, &modelObject, &stepper,
                                   &onsets, &islands, &threads))
    return NULL;
  softOptions o;
  if (!soft_options(stepper, onsets, islands, threads, &o)) return NULL;
  const pdModel* model = ((pdPyModel*)modelObject)->model;
  pdState* state = soft_state_create(model, &o);
  pdPyState* s = state_alloc(modelObject, model, state, false);
  if (!s) pd_state_free(state);
  return (PyObject*)s;
}

static void state_dealloc(pdPyState* self) {
  if (!self->borrowed) pd_state_free(self->state);
  Py_XDECREF(self->modelObject);
  PyObject_Free(self);
}

static bool state_usable(const pdPyState* self) {
  if (self->state) return true;
  PyErr_SetString(PyExc_RuntimeError, "this State belonged to a run's callback and is no longer valid");
  return false;
}

static bool state_owned(const pdPyState* self) {
  if (!state_usable(self)) return false;
  if (!self->borrowed) return true;
  PyErr_SetString(PyExc_RuntimeError, "a callback's State is read-only: it cannot advance or reset the run");
  return false;
}

static PyObject* state_advance(pdPyState* self, PyObject* args, PyObject* kwargs) {
  static char* names[] = {"t_end", "callback", "catch_interrupt", NULL};
  double tEnd;
  PyObject* callback = Py_None;
  int catchInterrupt = PyThread_get_thread_ident() == pdPyMainThread;
  if (!PyArg_ParseTupleAndKeywords(args, kwargs, "d|Op:advance", names, &tEnd, &callback, &catchInterrupt))
    return NULL;
  if (!state_owned(self)) return NULL;
  if (!(tEnd >= self->state->t) || !isfinite(tEnd)) {
    PyErr_Format(PyExc_ValueError, "t_end must be finite and >= the state's time t = %.17g s", self->state->t);
    return NULL;
  }
  if (callback != Py_None && !PyCallable_Check(callback)) {
    PyErr_SetString(PyExc_TypeError, "callback must be callable or None");
    return NULL;
  }
  recorder r = {0};
  if (callback != Py_None) {
    r.callback = callback;
    r.view = state_alloc(NULL, self->model, self->state, true);
    if (!r.view) return NULL;
  }
  pdPyInterruptScope scope;
  pd_py_interrupt_begin(&scope, catchInterrupt);
  r.thread = PyEval_SaveThread();
  bool completed = pd_advance(self->model, self->state, tEnd, observe, &r);  // observe also checks the interrupt flag
  PyEval_RestoreThread(r.thread);
  pd_py_interrupt_end(&scope);
  if (r.view) {
    r.view->state = NULL;
    Py_DECREF(r.view);
  }
  if (r.callbackFailed) return NULL;
  if (scope.caught && pdPyInterrupted) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    return NULL;
  }
  return PyBool_FromLong(completed);
}

static PyObject* state_reset(pdPyState* self, PyObject* noArgs) {
  (void)noArgs;
  if (!state_owned(self)) return NULL;
  pd_state_reset(self->model, self->state);
  Py_RETURN_NONE;
}

// A writable C-contiguous buffer of exactly `count` doubles from `out`, or NULL with an exception.
static bool writable_doubles(PyObject* out, Py_ssize_t count, Py_buffer* view) {
  if (PyObject_GetBuffer(out, view, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) return false;
  if (view->len != count * (Py_ssize_t)sizeof(double) || !view->format || strcmp(view->format, "d") != 0) {
    PyBuffer_Release(view);
    PyErr_Format(PyExc_ValueError, "out must be a C-contiguous float64 array of %zd numbers", count);
    return false;
  }
  return true;
}

static PyObject* state_poses(pdPyState* self, PyObject* args, PyObject* kwargs) {
  static char* names[] = {"out", NULL};
  PyObject* out = Py_None;
  if (!PyArg_ParseTupleAndKeywords(args, kwargs, "|O:poses", names, &out)) return NULL;
  if (!state_usable(self)) return NULL;
  const pdModel* m = self->model;
  Py_ssize_t count = (Py_ssize_t)m->movingCount * POSE_DOUBLES;
  if (out != Py_None) {
    Py_buffer view;
    if (!writable_doubles(out, count, &view)) return NULL;
    for (int j = 0; j < m->movingCount; ++j)
      pose_write((double*)view.buf + (size_t)j * POSE_DOUBLES, pd_state_body(m, self->state, m->movingBodies[j]));
    PyBuffer_Release(&view);
    Py_INCREF(out);
    return out;
  }
  double* data = malloc(sizeof(double) * (size_t)(count > 0 ? count : 1));
  if (!data) return PyErr_NoMemory();
  for (int j = 0; j < m->movingCount; ++j)
    pose_write(data + (size_t)j * POSE_DOUBLES, pd_state_body(m, self->state, m->movingBodies[j]));
  return pd_py_buffer_adopt(data, count * (Py_ssize_t)sizeof(double));
}

static PyObject* state_body(pdPyState* self, PyObject* args) {
  int i;
  if (!PyArg_ParseTuple(args, "i:body", &i)) return NULL;
  if (!state_usable(self)) return NULL;
  if (i < 0 || i >= self->model->bodyCount) {
    PyErr_Format(PyExc_IndexError, "body index %d out of range 0..%d", i, self->model->bodyCount - 1);
    return NULL;
  }
  pdBodyState b = pd_state_body(self->model, self->state, i);
  return Py_BuildValue("((ddd)(dddd)(ddd)(ddd))", b.x.x, b.x.y, b.x.z, b.q.w, b.q.x, b.q.y, b.q.z, b.v.x, b.v.y, b.v.z,
                       b.w.x, b.w.y, b.w.z);
}

static PyObject* state_contacts(pdPyState* self, PyObject* noArgs) {
  (void)noArgs;
  if (!state_usable(self)) return NULL;
  int n = pd_state_contact_count(self->state);
  pdPyContact* c = malloc(sizeof(pdPyContact) * (size_t)(n > 0 ? n : 1));
  if (!c) return PyErr_NoMemory();
  long sample = self->state->nextSample > 0 ? self->state->nextSample - 1 : 0;
  for (int j = 0; j < n; ++j) contact_write(&c[j], self->state, j, sample);
  return pd_py_buffer_adopt(c, (Py_ssize_t)n * (Py_ssize_t)sizeof(pdPyContact));
}

static PyObject* state_energy(pdPyState* self, PyObject* noArgs) {
  (void)noArgs;
  if (!state_usable(self)) return NULL;
  return PyFloat_FromDouble(pd_state_energy(self->model, self->state));
}

static PyObject* state_get_t(pdPyState* self, void* closure) {
  (void)closure;
  return state_usable(self) ? PyFloat_FromDouble(self->state->t) : NULL;
}

static PyObject* state_get_flag(pdPyState* self, void* closure) {
  if (!state_usable(self)) return NULL;
  return PyBool_FromLong(closure ? self->state->stopped : self->state->failed);
}

static PyObject* state_get_warnings(pdPyState* self, void* closure) {
  (void)closure;
  if (!state_usable(self)) return NULL;
  PyObject* d = PyDict_New();
  for (int w = 0; d && w < pd_warnCount; ++w) {
    PyObject* v = PyLong_FromLong(self->state->warnings[w]);
    if (!v || PyDict_SetItemString(d, pdWarningNames[w], v) < 0) Py_CLEAR(d);
    Py_XDECREF(v);
  }
  return d;
}

static PyObject* state_get_counters(pdPyState* self, void* closure) {
  (void)closure;
  if (!state_usable(self)) return NULL;
  const pdCounters* c = &self->state->count;
  return Py_BuildValue("{s:l,s:l,s:l,s:l,s:l,s:l,s:l,s:d}", "accepted", c->accepted, "rejected", c->rejected,
                       "derivatives", c->derivatives, "samples", c->samples, "contacts_made", c->contactsMade,
                       "breaks_force", c->breaksForce, "breaks_geometry", c->breaksGeometry, "body_seconds_asleep",
                       c->bodySecondsAsleep);
}

static PyObject* state_get_model(pdPyState* self, void* closure) {
  (void)closure;
  if (!self->modelObject) Py_RETURN_NONE;
  Py_INCREF(self->modelObject);
  return self->modelObject;
}

static PyObject* state_get_moving(pdPyState* self, void* closure) {
  (void)closure;
  return PyLong_FromLong(self->model->movingCount);
}

static PyMethodDef stateMethods[] = {
    {"advance", (PyCFunction)(void (*)(void))state_advance, METH_VARARGS | METH_KEYWORDS,
     "advance(t_end, callback=None, catch_interrupt=<in the main thread>): pd_advance to t_end (s); callback(state) "
     "at every output sample, returning False stops; Ctrl-C stops at the next sample and raises KeyboardInterrupt. "
     "Returns True when t reached t_end."},
    {"reset", (PyCFunction)state_reset, METH_NOARGS, "back to t = 0 (pd_state_reset; the options stay)"},
    {"poses", (PyCFunction)(void (*)(void))state_poses, METH_VARARGS | METH_KEYWORDS,
     "poses(out=None): every moving body's x, q, v, w as 13 float64 each (a Buffer, or written into out)"},
    {"body", (PyCFunction)state_body, METH_VARARGS, "body(i): (x, q, v, w) of model body i, fixed ones included"},
    {"contacts", (PyCFunction)state_contacts, METH_NOARGS, "the active contacts as records (contact_layout())"},
    {"energy", (PyCFunction)state_energy, METH_NOARGS, "kinetic + gravitational + spring energy, J"},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef stateGetSet[] = {
    {"t", (getter)state_get_t, NULL, "the state's time, s", NULL},
    {"failed", (getter)state_get_flag, NULL, "the run could not continue (see warnings)", NULL},
    {"stopped", (getter)state_get_flag, NULL, "a callback asked to stop", (void*)1},
    {"warnings", (getter)state_get_warnings, NULL, "counted warnings by name", NULL},
    {"counters", (getter)state_get_counters, NULL, "step and contact counts", NULL},
    {"model", (getter)state_get_model, NULL, "the Model (None for a callback's State)", NULL},
    {"moving_count", (getter)state_get_moving, NULL, "moving bodies", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject pdPyStateType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "polydyn._polydyn.State",
    .tp_basicsize = sizeof(pdPyState),
    .tp_dealloc = (destructor)state_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "State(model, *, stepper=None, onsets=None, islands=None, threads=1): the mutable state of a soft "
              "engine run (polydyn/state.h); one thread at a time.",
    .tp_new = state_new,
    .tp_methods = stateMethods,
    .tp_getset = stateGetSet,
};

// ---------------------------------------------------------------- run()

static double wall_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// The summary.json text of a soft run (malloc'd), or NULL when memory ran out.
static char* summary_text(const pdModel* model, const pdState* state, const pdRunInfo* info) {
  char* text = NULL;
  size_t size = 0;
  FILE* f = open_memstream(&text, &size);
  if (!f) return NULL;
  pd_write_summary_json(f, model, state, info);
  if (fclose(f) != 0) {
    free(text);
    return NULL;
  }
  return text;
}

// The reference engines keep global state in their libraries: one run at a time per process.
static PyThread_type_lock refLock = NULL;

static PyObject* run(PyObject* module, PyObject* args, PyObject* kwargs) {
  (void)module;
  static char* names[] = {"model", "engine", "variant", "step", "ode_friction", "stepper", "onsets", "islands",
                          "threads", "contacts", "callback", "out", "catch_interrupt", NULL};
  PyObject* modelObject;
  const char *engine = "soft", *variant = NULL, *odeFriction = NULL, *stepper = NULL, *onsets = NULL, *islands = NULL;
  double step = 0.0;
  int threads = 1, contacts = 1, catchInterrupt = 0;
  PyObject *callback = Py_None, *outObject = Py_None;
  if (!PyArg_ParseTupleAndKeywords(args, kwargs, "O!|$szdzzzzipOOp:run", names, &pdPyModelType, &modelObject, &engine,
                                   &variant, &step, &odeFriction, &stepper, &onsets, &islands, &threads, &contacts,
                                   &callback, &outObject, &catchInterrupt))
    return NULL;
  const pdModel* model = ((pdPyModel*)modelObject)->model;
  bool soft = strcmp(engine, "soft") == 0;
  const pdRefAdapter* adapter = NULL;
  if (!soft) {
    if (strcmp(engine, "ode") != 0 && strcmp(engine, "bullet") != 0)
      return PyErr_Format(PyExc_ValueError, "engine must be soft, ode or bullet, not '%s'", engine);
    adapter = pd_ref_adapter(engine);
    if (!adapter) return PyErr_Format(PyExc_ValueError, "engine %s: this build of polydyn has no %s adapter", engine, engine);
  }
  if (soft && (variant || step > 0.0 || odeFriction))
    return PyErr_Format(PyExc_ValueError, "variant, step and ode_friction are for engine='ode' or 'bullet'");
  if (!soft && (stepper || onsets || islands || threads != 1))
    return PyErr_Format(PyExc_ValueError, "stepper, onsets, islands and threads are for the soft engine");
  if (!soft && outObject == Py_None)
    return PyErr_Format(PyExc_ValueError, "a reference engine's run needs out (its summary is written there)");
  softOptions so;
  if (soft && !soft_options(stepper, onsets, islands, threads, &so)) return NULL;
  pdRefOptions ref = {.variant = pd_refNative, .step = PD_REF_DEFAULT_STEP, .odeFriction = pd_odeFrictionPyramid};
  if (variant && strcmp(variant, "matched") == 0) ref.variant = pd_refMatched;
  else if (variant && strcmp(variant, "native") != 0)
    return PyErr_Format(PyExc_ValueError, "variant must be native or matched, not '%s'", variant);
  if (!(step >= 0.0) || !isfinite(step)) return PyErr_Format(PyExc_ValueError, "step must be > 0");
  if (step > 0.0) ref.step = step;
  if (odeFriction && strcmp(engine, "ode") != 0) return PyErr_Format(PyExc_ValueError, "ode_friction is for engine='ode'");
  if (odeFriction && strcmp(odeFriction, "aligned") == 0) ref.odeFriction = pd_odeFrictionAligned;
  else if (odeFriction && strcmp(odeFriction, "pyramid") != 0)
    return PyErr_Format(PyExc_ValueError, "ode_friction must be pyramid or aligned, not '%s'", odeFriction);
  if (callback != Py_None && !PyCallable_Check(callback))
    return PyErr_Format(PyExc_TypeError, "callback must be callable or None");
  PyObject* outBytes = NULL;
  if (outObject != Py_None && !PyUnicode_FSConverter(outObject, &outBytes)) return NULL;

  recorder r = {.record = true, .recordContacts = soft && contacts, .moving = model->movingCount};
  pdError err = {0};
  if (outBytes) {
    r.writer = pd_run_open(PyBytes_AS_STRING(outBytes), &err);
    if (!r.writer) {
      Py_DECREF(outBytes);
      return pd_py_raise_error(&err);
    }
  }
  if (callback != Py_None) {
    r.callback = callback;
    r.view = state_alloc(NULL, model, NULL, true);
    if (!r.view) {
      pd_run_abort(r.writer);
      Py_XDECREF(outBytes);
      return NULL;
    }
  }
  pdPyInterruptScope scope;
  pd_py_interrupt_begin(&scope, catchInterrupt);
  bool completed = false, ok = true, refused = false;
  double wall = 0.0;
  char* summary = NULL;
  long steps = 0;
  if (!soft && !refLock && !(refLock = PyThread_allocate_lock())) {
    pd_py_interrupt_end(&scope);
    pd_run_abort(r.writer);
    Py_XDECREF(outBytes);
    Py_XDECREF(r.view);
    return PyErr_NoMemory();
  }
  r.thread = PyEval_SaveThread();
  if (soft) {
    pdState* state = soft_state_create(model, &so);
    double energyStart = pd_state_energy(model, state);
    double t0 = wall_seconds();
    completed = pd_advance(model, state, model->settings.tend, observe, &r);
    if (r.writer) pd_run_drain(r.writer);
    wall = wall_seconds() - t0;
    steps = state->count.accepted;
    pdRunInfo info = {.engine = "polydyn-soft", .energyStart = energyStart,
                      .energyEnd = pd_state_energy(model, state), .wallSeconds = wall, .completed = completed};
    bool stoppedEarly = pdPyInterrupted || r.callbackFailed || r.noMemory || r.writeFailed;
    if (!stoppedEarly) summary = summary_text(model, state, &info);
    if (r.writer) {
      if (stoppedEarly) pd_run_abort(r.writer);
      else ok = pd_run_finish(r.writer, model, state, &info, &err);
    }
    pd_state_free(state);
  } else {
    PyThread_acquire_lock(refLock, WAIT_LOCK);
    pdRefRunStats stats = {0};
    double t0 = wall_seconds();
    ok = pd_ref_run(model, adapter, &ref, r.writer, observe, &r, &stats, &err);
    wall = wall_seconds() - t0;
    PyThread_release_lock(refLock);
    completed = ok && stats.completed;
    refused = stats.refused;
    steps = stats.steps;
  }
  PyEval_RestoreThread(r.thread);
  pd_py_interrupt_end(&scope);
  Py_XDECREF(outBytes);
  if (r.view) {
    r.view->state = NULL;
    Py_DECREF(r.view);
  }
  PyObject* result = NULL;
  if (r.callbackFailed) {
    // the callback's exception is set
  } else if (scope.caught && pdPyInterrupted) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);
  } else if (r.noMemory) {
    PyErr_NoMemory();
  } else if (refused) {
    pd_py_raise_error(&err);
  } else if (!ok && !r.callbackStopped) {
    PyErr_Format(PyExc_OSError, "%s: %s", err.file, err.message);
  } else {
    PyObject* t = pd_py_buffer_adopt(r.t, (Py_ssize_t)r.samples * (Py_ssize_t)sizeof(double));
    r.t = NULL;
    PyObject* poses = pd_py_buffer_adopt(r.poses, (Py_ssize_t)r.samples * r.moving * ROW_SLOTS * (Py_ssize_t)sizeof(double));
    r.poses = NULL;
    PyObject* cs = pd_py_buffer_adopt(r.contact, (Py_ssize_t)r.contacts * (Py_ssize_t)sizeof(pdPyContact));
    r.contact = NULL;
    PyObject* summaryObject = summary ? PyUnicode_FromString(summary) : (Py_INCREF(Py_None), Py_None);
    if (t && poses && cs && summaryObject)
      result = Py_BuildValue("{s:O,s:O,s:l,s:O,s:l,s:O,s:O,s:d,s:l}", "t", t, "poses", poses, "samples", r.samples,
                             "contacts", cs, "contact_count", r.contacts, "completed", completed ? Py_True : Py_False,
                             "summary", summaryObject, "wall_seconds", wall, "steps", steps);
    Py_XDECREF(t);
    Py_XDECREF(poses);
    Py_XDECREF(cs);
    Py_XDECREF(summaryObject);
  }
  free(summary);
  recorder_free(&r);
  return result;
}

static PyObject* contact_layout(PyObject* module, PyObject* noArgs) {
  (void)module, (void)noArgs;
  return Py_BuildValue(
      "{s:n,s:[(sns),(sns),(sns),(sns),(sns),(sns),(sns),(sns),(sns),(sns),(sns),(sns),(sns)]}", "itemsize",
      (Py_ssize_t)sizeof(pdPyContact), "fields", "t", (Py_ssize_t)offsetof(pdPyContact, t), "f8", "sample",
      (Py_ssize_t)offsetof(pdPyContact, sample), "i8", "body_a", (Py_ssize_t)offsetof(pdPyContact, bodyA), "i4",
      "body_b", (Py_ssize_t)offsetof(pdPyContact, bodyB), "i4", "feat_a", (Py_ssize_t)offsetof(pdPyContact, featureA),
      "i4", "feat_b", (Py_ssize_t)offsetof(pdPyContact, featureB), "i4", "point",
      (Py_ssize_t)offsetof(pdPyContact, point), "(3,)f8", "normal", (Py_ssize_t)offsetof(pdPyContact, normal), "(3,)f8",
      "depth", (Py_ssize_t)offsetof(pdPyContact, depth), "f8", "fn", (Py_ssize_t)offsetof(pdPyContact, fn), "f8", "ft",
      (Py_ssize_t)offsetof(pdPyContact, ft), "(3,)f8", "edge_edge", (Py_ssize_t)offsetof(pdPyContact, edgeEdge), "?",
      "slip", (Py_ssize_t)offsetof(pdPyContact, slip), "?");
}

PyMethodDef pdPyStateFunctions[] = {
    {"run", (PyCFunction)(void (*)(void))run, METH_VARARGS | METH_KEYWORDS,
     "run(model, *, engine='soft', ...): the whole run recorded (the package's polydyn.run wraps it)"},
    {"contact_layout", contact_layout, METH_NOARGS, "the contact records' fields: (name, byte offset, dtype)"},
    {NULL, NULL, 0, NULL},
};
