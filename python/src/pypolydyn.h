// polydyn for Python — what the extension's files share (python/src).
//
// The extension `polydyn._polydyn` wraps the public C API (engine/include/polydyn, refcheck and gedanken
// headers); the package `polydyn` (python/polydyn) builds its NumPy arrays and result tables on top of it.
// Arrays cross the boundary without a copy: C fills one malloc'd block, a pdPyBuffer owns it and exports it
// through the buffer protocol, and NumPy views it (numpy.frombuffer). The GIL is released while C runs; an
// observer that calls back into Python takes it back for the call only.
#pragma once

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <signal.h>
#include <stdbool.h>

#include "polydyn/model.h"
#include "polydyn/scene.h"
#include "polydyn/state.h"

// ---------------------------------------------------------------- errors (module.c)

// polydyn.SceneError: bad input, carrying file, line, col and message; str() is `FILE:LINE:COL: message`.
extern PyObject* pdPySceneError;
// Raises SceneError from a filled pdError; returns NULL.
PyObject* pd_py_raise_error(const pdError* err);

// ---------------------------------------------------------------- owned memory as a buffer (module.c)

typedef struct pdPyBuffer {
  PyObject_HEAD
  void* data;       // malloc'd, owned; freed with the object
  Py_ssize_t size;  // bytes
} pdPyBuffer;
extern PyTypeObject pdPyBufferType;
// Takes ownership of `data` (size bytes; NULL allowed when size is 0). On failure frees data and returns NULL.
PyObject* pd_py_buffer_adopt(void* data, Py_ssize_t size);

// ---------------------------------------------------------------- scene and model (module.c)

typedef struct pdPyScene {
  PyObject_HEAD
  pdScene* scene;
} pdPyScene;
extern PyTypeObject pdPySceneType;

typedef struct pdPyModel {
  PyObject_HEAD
  pdModel* model;
} pdPyModel;
extern PyTypeObject pdPyModelType;

// The settings a caller may override when a scene is compiled (0: as the scene says), as `polydyn run
// --tend --sample` applies them.
typedef struct pdPyOverrides {
  double tend, sample, tol;
} pdPyOverrides;
// Compiles `scene` with the overrides; NULL with SceneError set on bad input. Holds the GIL.
pdModel* pd_py_compile(pdScene* scene, const pdPyOverrides* overrides);

// ---------------------------------------------------------------- state and runs (state.c)

typedef struct pdPyState {
  PyObject_HEAD
  PyObject* modelObject;   // the pdPyModel this state belongs to (strong reference), or NULL for a borrowed state
  const pdModel* model;
  pdState* state;          // owned unless `borrowed`
  bool borrowed;           // a run's state handed to a callback: valid only during the call
} pdPyState;
extern PyTypeObject pdPyStateType;

extern PyMethodDef pdPyStateFunctions[];  // run(), contact_layout()

// Interrupts while C runs: SIGINT sets the flag (the commands' own convention: the observer returns false at the
// next sample). pd_py_interrupt_begin installs the handler when `catch` (the caller is the main thread) and
// clears the flag; pd_py_interrupt_end puts Python's handler back. Returns the flag's address.
extern volatile sig_atomic_t pdPyInterrupted;
extern unsigned long pdPyMainThread;  // the thread that imported the module (Python's main thread)
typedef struct pdPyInterruptScope {
  bool caught;
  struct sigaction previous;
} pdPyInterruptScope;
void pd_py_interrupt_begin(pdPyInterruptScope* scope, bool catchSignal);
void pd_py_interrupt_end(pdPyInterruptScope* scope);

// ---------------------------------------------------------------- the bench (bench.c)

extern PyMethodDef pdPyBenchFunctions[];  // oracle_pair(), oracle_scene(), oracle_random(), gedanken(), command()
