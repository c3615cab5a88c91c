// polydyn — the library's version (PD_VERSION_* come from the CMake project version, engine/CMakeLists.txt).
#include "polydyn/api.h"

const char* pd_version(void) { return PD_VERSION; }

pdVersion pd_version_numbers(void) {
  return (pdVersion){PD_VERSION_MAJOR, PD_VERSION_MINOR, PD_VERSION_PATCH};
}
