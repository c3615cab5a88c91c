// polydyn — PD_API marks the functions and data of the public API.
//
// The engine is compiled with hidden symbol visibility: libpolydyn.so exports exactly the declarations
// marked PD_API in these headers, so an embedding program cannot come to depend on an internal function
// (engine/src) by accident. The static library, libpolydyn.a, holds the same objects.
#pragma once

#if defined(__GNUC__)
#define PD_API __attribute__((visibility("default")))
#else
#define PD_API
#endif
