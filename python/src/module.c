// polydyn for Python — the module: errors, owned buffers, Scene and Model (python/src/pypolydyn.h).
#include <math.h>
#include <string.h>

#include "pypolydyn.h"

PyObject* pdPySceneError = NULL;

PyObject* pd_py_raise_error(const pdError* err) {
  char text[3 * PD_ERROR_MESSAGE_MAX];
  if (err->line > 0)
    snprintf(text, sizeof text, "%s:%d:%d: %s", err->file, err->line, err->col, err->message);
  else
    snprintf(text, sizeof text, "%s: %s", err->file, err->message);
  PyObject* e = PyObject_CallFunction(pdPySceneError, "s", text);
  if (!e) return NULL;
  PyObject* file = PyUnicode_DecodeFSDefault(err->file);
  PyObject* line = PyLong_FromLong(err->line);
  PyObject* col = PyLong_FromLong(err->col);
  PyObject* message = PyUnicode_FromString(err->message);
  if (file && line && col && message && PyObject_SetAttrString(e, "file", file) == 0 &&
      PyObject_SetAttrString(e, "line", line) == 0 && PyObject_SetAttrString(e, "col", col) == 0 &&
      PyObject_SetAttrString(e, "message", message) == 0)
    PyErr_SetObject(pdPySceneError, e);
  Py_XDECREF(file);
  Py_XDECREF(line);
  Py_XDECREF(col);
  Py_XDECREF(message);
  Py_DECREF(e);
  return NULL;
}

// ---------------------------------------------------------------- Buffer

static void buffer_dealloc(pdPyBuffer* self) {
  free(self->data);
  Py_TYPE(self)->tp_free((PyObject*)self);
}

static int buffer_get(pdPyBuffer* self, Py_buffer* view, int flags) {
  return PyBuffer_FillInfo(view, (PyObject*)self, self->data, self->size, 0, flags);
}

static PyBufferProcs bufferProcs = {.bf_getbuffer = (getbufferproc)buffer_get};

PyTypeObject pdPyBufferType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "polydyn._polydyn.Buffer",
    .tp_basicsize = sizeof(pdPyBuffer),
    .tp_dealloc = (destructor)buffer_dealloc,
    .tp_as_buffer = &bufferProcs,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Memory filled by polydyn's C code, viewed by NumPy without a copy.",
};

PyObject* pd_py_buffer_adopt(void* data, Py_ssize_t size) {
  pdPyBuffer* b = PyObject_New(pdPyBuffer, &pdPyBufferType);
  if (!b) {
    free(data);
    return NULL;
  }
  b->data = data;
  b->size = size;
  return (PyObject*)b;
}

// ---------------------------------------------------------------- Scene

static void scene_dealloc(pdPyScene* self) {
  pd_scene_free(self->scene);
  Py_TYPE(self)->tp_free((PyObject*)self);
}

static PyObject* scene_wrap(PyTypeObject* type, pdScene* scene, const pdError* err) {
  if (!scene) return pd_py_raise_error(err);
  pdPyScene* s = (pdPyScene*)type->tp_alloc(type, 0);
  if (!s) {
    pd_scene_free(scene);
    return NULL;
  }
  s->scene = scene;
  return (PyObject*)s;
}

static PyObject* scene_from_file(PyObject* type, PyObject* args) {
  PyObject* pathObject;
  if (!PyArg_ParseTuple(args, "O&:from_file", PyUnicode_FSConverter, &pathObject)) return NULL;
  pdError err = {0};
  pdScene* scene;
  Py_BEGIN_ALLOW_THREADS
  scene = pd_scene_parse_file(PyBytes_AS_STRING(pathObject), &err);
  Py_END_ALLOW_THREADS
  Py_DECREF(pathObject);
  return scene_wrap((PyTypeObject*)type, scene, &err);
}

static PyObject* scene_from_string(PyObject* type, PyObject* args, PyObject* kwargs) {
  static char* names[] = {"text", "name", NULL};
  const char* text;
  Py_ssize_t length;
  const char* name = "<string>";
  if (!PyArg_ParseTupleAndKeywords(args, kwargs, "s#|s:from_string", names, &text, &length, &name)) return NULL;
  pdError err = {0};
  pdScene* scene = pd_scene_parse_buffer(name, text, (size_t)length, &err);
  return scene_wrap((PyTypeObject*)type, scene, &err);
}

static PyObject* settings_dict(const pdSceneSettings* s) {
  return Py_BuildValue("{s:(ddd),s:d,s:d,s:d,s:d,s:d,s:d,s:d,s:d,s:O}", "gravity", s->gravity[0], s->gravity[1],
                       s->gravity[2], "tend", s->tend, "tol", s->tol, "dt", s->dt, "dtmin", s->dtmin, "dtmax",
                       s->dtmax, "sample", s->sample, "vmax", s->vmax, "deflection", s->deflection, "sleep",
                       s->sleep ? Py_True : Py_False);
}

static PyObject* scene_get_path(pdPyScene* self, void* closure) {
  (void)closure;
  return PyUnicode_DecodeFSDefault(self->scene->path);
}

static PyObject* scene_get_settings(pdPyScene* self, void* closure) {
  (void)closure;
  return settings_dict(&self->scene->settings);
}

static PyObject* scene_get_names(pdPyScene* self, void* closure) {
  (void)closure;
  PyObject* list = PyList_New(self->scene->objectCount);
  for (int i = 0; list && i < self->scene->objectCount; ++i) {
    PyObject* name = PyUnicode_FromString(self->scene->objects[i].name);
    if (!name) {
      Py_CLEAR(list);
      break;
    }
    PyList_SET_ITEM(list, i, name);
  }
  return list;
}

static PyMethodDef sceneMethods[] = {
    {"from_file", scene_from_file, METH_VARARGS | METH_CLASS,
     "Scene.from_file(path): parse a scene file; SceneError (FILE:LINE:COL: message) on bad input."},
    {"from_string", (PyCFunction)(void (*)(void))scene_from_string, METH_VARARGS | METH_KEYWORDS | METH_CLASS,
     "Scene.from_string(text, name='<string>'): parse a scene held in a string; name stands for the file in "
     "messages."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef sceneGetSet[] = {
    {"path", (getter)scene_get_path, NULL, "the file name used in messages", NULL},
    {"settings", (getter)scene_get_settings, NULL, "the settings as written (defaults filled in), SI units", NULL},
    {"names", (getter)scene_get_names, NULL, "the objects' names in file order", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject pdPySceneType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "polydyn._polydyn.Scene",
    .tp_basicsize = sizeof(pdPyScene),
    .tp_dealloc = (destructor)scene_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "A parsed scene (polydyn/scene.h): Scene.from_file(path) or Scene.from_string(text).",
    .tp_methods = sceneMethods,
    .tp_getset = sceneGetSet,
};

// ---------------------------------------------------------------- Model

pdModel* pd_py_compile(pdScene* scene, const pdPyOverrides* o) {
  pdSceneSettings saved = scene->settings;
  if (o->tend > 0.0) scene->settings.tend = o->tend;
  if (o->sample > 0.0) scene->settings.sample = o->sample;
  if (o->tol > 0.0) scene->settings.tol = o->tol;
  pdError err = {0};
  pdModel* model = NULL;
  // the bound `polydyn run` sets: the samples of one run must fit in memory
  if (scene->settings.tend * scene->settings.sample > 1e8)
    pd_error_set(&err, scene->path, 0, 0, "too many output samples (tend × sample > 1e8)");
  else
    model = pd_model_compile(scene, &err);
  scene->settings = saved;
  if (!model) pd_py_raise_error(&err);
  return model;
}

static bool optional_positive(PyObject* value, const char* what, double* out) {
  *out = 0.0;
  if (!value || value == Py_None) return true;
  double v = PyFloat_AsDouble(value);
  if (v == -1.0 && PyErr_Occurred()) return false;
  if (!(v > 0.0) || !isfinite(v)) {
    PyErr_Format(PyExc_ValueError, "%s must be a finite number > 0", what);
    return false;
  }
  *out = v;
  return true;
}

static PyObject* model_new(PyTypeObject* type, PyObject* args, PyObject* kwargs) {
  static char* names[] = {"scene", "tend", "sample", "tol", NULL};
  PyObject *sceneObject, *tend = NULL, *sample = NULL, *tol = NULL;
  if (!PyArg_ParseTupleAndKeywords(args, kwargs, "O!|OOO:Model", names, &pdPySceneType, &sceneObject, &tend, &sample,
                                   &tol))
    return NULL;
  pdPyOverrides o;
  if (!optional_positive(tend, "tend", &o.tend) || !optional_positive(sample, "sample", &o.sample) ||
      !optional_positive(tol, "tol", &o.tol))
    return NULL;
  pdModel* model = pd_py_compile(((pdPyScene*)sceneObject)->scene, &o);
  if (!model) return NULL;
  pdPyModel* m = (pdPyModel*)type->tp_alloc(type, 0);
  if (!m) {
    pd_model_free(model);
    return NULL;
  }
  m->model = model;
  return (PyObject*)m;
}

static void model_dealloc(pdPyModel* self) {
  pd_model_free(self->model);
  Py_TYPE(self)->tp_free((PyObject*)self);
}

static PyObject* vec3(pdVec3 v) { return Py_BuildValue("(ddd)", v.x, v.y, v.z); }

static PyObject* mat3(const pdMat3* m) {
  return Py_BuildValue("((ddd)(ddd)(ddd))", m->m[0][0], m->m[0][1], m->m[0][2], m->m[1][0], m->m[1][1], m->m[1][2],
                       m->m[2][0], m->m[2][1], m->m[2][2]);
}

static PyObject* body_dict(const pdBody* b) {
  PyObject* x0 = vec3(b->x0);
  PyObject* v0 = vec3(b->v0);
  PyObject* w0 = vec3(b->w0);
  PyObject* inertia = mat3(&b->inertia);
  PyObject* d = NULL;
  if (x0 && v0 && w0 && inertia)
    d = Py_BuildValue("{s:s,s:s,s:O,s:i,s:d,s:d,s:d,s:d,s:O,s:(ddd),s:O,s:(dddd),s:O,s:O,s:d,s:d,s:i,s:i}", "name",
                      b->name, "color", b->color, "fixed", b->fixed ? Py_True : Py_False, "state_index", b->stateIndex,
                      "mass", b->mass, "volume", b->volume, "density", b->density, "size", b->size, "inertia",
                      inertia, "principal", b->principal[0], b->principal[1], b->principal[2], "x0", x0, "q0",
                      b->q0.w, b->q0.x, b->q0.y, b->q0.z, "v0", v0, "w0", w0, "mu", b->used.mu, "restitution",
                      b->used.restitution, "vertices", b->shape.vertexCount, "faces", b->shape.faceCount);
  Py_XDECREF(x0);
  Py_XDECREF(v0);
  Py_XDECREF(w0);
  Py_XDECREF(inertia);
  return d;
}

static PyObject* model_get_bodies(pdPyModel* self, void* closure) {
  (void)closure;
  PyObject* list = PyList_New(self->model->bodyCount);
  for (int i = 0; list && i < self->model->bodyCount; ++i) {
    PyObject* d = body_dict(&self->model->bodies[i]);
    if (!d) {
      Py_CLEAR(list);
      break;
    }
    PyList_SET_ITEM(list, i, d);
  }
  return list;
}

static PyObject* model_get_moving(pdPyModel* self, void* closure) {
  (void)closure;
  PyObject* t = PyTuple_New(self->model->movingCount);
  for (int k = 0; t && k < self->model->movingCount; ++k) PyTuple_SET_ITEM(t, k, PyLong_FromLong(self->model->movingBodies[k]));
  return t;
}

static PyObject* model_get_settings(pdPyModel* self, void* closure) {
  (void)closure;
  const pdSettings* s = &self->model->settings;
  return Py_BuildValue("{s:(ddd),s:d,s:d,s:d,s:d,s:d,s:d,s:d,s:O,s:d,s:O}", "gravity", s->gravity.x, s->gravity.y,
                       s->gravity.z, "tend", s->tend, "tol", s->tol, "dt", s->dt, "dtmin", s->dtmin, "dtmax", s->dtmax,
                       "sample", s->sampleRate, "vmax", s->vmax, "vmax_estimated",
                       s->vmaxEstimated ? Py_True : Py_False, "deflection", s->deflection, "sleep",
                       s->sleep ? Py_True : Py_False);
}

static PyObject* model_get_path(pdPyModel* self, void* closure) {
  (void)closure;
  return PyUnicode_DecodeFSDefault(self->model->scenePath);
}

static PyObject* model_pair_contact(pdPyModel* self, PyObject* args) {
  int a, b;
  if (!PyArg_ParseTuple(args, "ii:pair_contact", &a, &b)) return NULL;
  const pdModel* m = self->model;
  if (a < 0 || b < 0 || a >= m->bodyCount || b >= m->bodyCount || a == b || (m->bodies[a].fixed && m->bodies[b].fixed)) {
    PyErr_SetString(PyExc_IndexError, "two different body indices, not both fixed");
    return NULL;
  }
  pdPairContact p = pd_model_pair_contact(m, a, b);
  return Py_BuildValue("{s:d,s:d,s:d,s:d,s:d,s:d,s:s,s:d,s:d,s:d,s:d,s:d,s:d}", "mu", p.mu, "kn", p.kn, "kt", p.kt,
                       "cn", p.cn, "ct", p.ct, "restitution", p.restitution, "restitution_source", p.restitutionSource,
                       "zeta_n", p.zetaN, "zeta_t", p.zetaT, "m_pair", p.massPair, "m_min", p.massMin, "period",
                       p.period, "delta_max", p.deltaMax);
}

static PyMethodDef modelMethods[] = {
    {"pair_contact", (PyCFunction)model_pair_contact, METH_VARARGS,
     "pair_contact(a, b): the contact constants of bodies a and b as used (SI units; polydyn/model.h)."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef modelGetSet[] = {
    {"bodies", (getter)model_get_bodies, NULL, "every body in scene order: a dict of its properties (SI units)", NULL},
    {"moving", (getter)model_get_moving, NULL, "the body index of each moving body, scene order", NULL},
    {"settings", (getter)model_get_settings, NULL, "the settings in force (SI units)", NULL},
    {"path", (getter)model_get_path, NULL, "the scene's file name", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject pdPyModelType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "polydyn._polydyn.Model",
    .tp_basicsize = sizeof(pdPyModel),
    .tp_dealloc = (destructor)model_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "Model(scene, tend=None, sample=None, tol=None): a scene compiled (polydyn/model.h), read-only; "
              "any number of States, in any threads, may share it.",
    .tp_new = model_new,
    .tp_methods = modelMethods,
    .tp_getset = modelGetSet,
};

// ---------------------------------------------------------------- the module

static struct PyModuleDef moduleDef = {PyModuleDef_HEAD_INIT, "_polydyn",
                                       "polydyn's C library (the package polydyn wraps it)", -1, NULL,
                                       NULL, NULL, NULL, NULL};

static int add_functions(PyObject* module, PyMethodDef* functions) {
  return PyModule_AddFunctions(module, functions);
}

PyMODINIT_FUNC PyInit__polydyn(void);
PyMODINIT_FUNC PyInit__polydyn(void) {
  PyTypeObject* types[] = {&pdPyBufferType, &pdPySceneType, &pdPyModelType, &pdPyStateType};
  for (size_t i = 0; i < sizeof types / sizeof types[0]; ++i)
    if (PyType_Ready(types[i]) < 0) return NULL;
  PyObject* m = PyModule_Create(&moduleDef);
  if (!m) return NULL;
  pdPyMainThread = PyThread_get_thread_ident();
  pdPySceneError = PyErr_NewExceptionWithDoc(
      "polydyn._polydyn.SceneError",
      "Bad input (a scene, a data file): str() is FILE:LINE:COL: message; attributes file, line, col, message.",
      PyExc_ValueError, NULL);
  if (!pdPySceneError || PyModule_AddObjectRef(m, "SceneError", pdPySceneError) < 0 ||
      PyModule_AddObjectRef(m, "Scene", (PyObject*)&pdPySceneType) < 0 ||
      PyModule_AddObjectRef(m, "Model", (PyObject*)&pdPyModelType) < 0 ||
      PyModule_AddObjectRef(m, "State", (PyObject*)&pdPyStateType) < 0 ||
      PyModule_AddObjectRef(m, "Buffer", (PyObject*)&pdPyBufferType) < 0 || add_functions(m, pdPyStateFunctions) < 0 ||
      add_functions(m, pdPyBenchFunctions) < 0 || PyModule_AddStringConstant(m, "engine_version", PD_PY_VERSION) < 0) {
    Py_DECREF(m);
    return NULL;
  }
  return m;
}
