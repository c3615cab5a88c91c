// polydyn — the public API: what every header of include/polydyn shares.
//
// Headers (C11; include the ones you use, each compiles on its own):
//   scene.h       parse a scene file or a scene held in memory (pdScene)
//   model.h       compile a scene into a read-only model: bodies, mass properties, contact material (pdModel)
//   state.h       the mutable state of a run, stepping it (pd_advance), reading poses and contacts (pdState)
//   output.h      run directories (trajectory.csv, contacts.csv, summary.json), as `polydyn run` writes them
//   polyhedron.h  convex polyhedra and exact mass properties
//   vecmath.h     vectors, quaternions, 3×3 matrices (mostly static inline)
//   error.h       pdError (bad input), PD_ASSERT (misuse) and its replaceable handler (pd_set_assert_fcn)
// examples/embed/main.c uses them end to end: scene → model → state → pd_advance with an observer.
//
// Conventions of every function:
// - Units SI (m, kg, s, N, rad) except where a comment says otherwise (the scene language's degrees).
// - Ownership: a function named *_create, *_compile, *_parse_* or *_open returns an object the caller owns
//   and frees with the matching *_free (or pd_run_finish / pd_run_abort), which accepts NULL. Pointers
//   inside a returned struct are owned by that struct; a caller reads them and never frees them.
//   pd_polyhedron_* fill a pdPolyhedron the caller holds; pd_polyhedron_free frees its arrays.
// - Errors: bad input (a scene file, a path) is reported through a pdError and a NULL/false return, never an
//   abort. Misuse by the caller (an index out of range, a NULL where one is not allowed) and running out of
//   memory abort through PD_ASSERT with a message on stderr.
// - Threads: no global mutable state but the assert handler (error.h), set once before threads start. A pdModel is
//   never written after pd_model_compile, so one model may drive many states in as many threads; a pdState belongs
//   to one thread at a time.
//
// PD_API marks the functions and data of the API. The engine is compiled with hidden symbol visibility:
// libpolydyn.so exports exactly the PD_API declarations of these headers, so an embedding program cannot
// come to depend on an internal function (engine/src) by accident. libpolydyn.a holds the same objects.
// Every header declares its functions inside PD_EXTERN_C_BEGIN/END: C linkage when included from C++.
// docs/embedding.md walks through an embedding program.
#pragma once

#if defined(__GNUC__)
#define PD_API __attribute__((visibility("default")))
#else
#define PD_API
#endif

#ifdef __cplusplus
#define PD_EXTERN_C_BEGIN extern "C" {
#define PD_EXTERN_C_END }
#else
#define PD_EXTERN_C_BEGIN
#define PD_EXTERN_C_END
#endif

// A function that does not return (C11 _Noreturn, C++ [[noreturn]]; the GNU attribute goes after PD_API in both).
#if defined(__GNUC__)
#define PD_NORETURN __attribute__((noreturn))
#elif defined(__cplusplus)
#define PD_NORETURN [[noreturn]]
#else
#define PD_NORETURN _Noreturn
#endif

PD_EXTERN_C_BEGIN

// The library's version, as the build's CMake project version: "MAJOR.MINOR.PATCH" (summary.json's "version",
// `polydyn --version`). 0.x: every minor version may change the API and the ABI.
PD_API const char* pd_version(void);

typedef struct pdVersion {
  int major, minor, patch;
} pdVersion;

// The same version as numbers.
PD_API pdVersion pd_version_numbers(void);

// The number of allocations (malloc, calloc, realloc, pd_grow) the engine has made in this process, counted in builds
// with PD_COUNT_ALLOCS (the dev and sanitizer presets; CMake option); -1 in builds without. The count is atomic, so
// states in several threads add to one total. A step never allocates once warmed up (state.h): tests check that the
// count stands still over pd_advance.
PD_API long pd_alloc_count(void);

PD_EXTERN_C_END
