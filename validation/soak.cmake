# The random-scene soak of `polydyn soak` (validation/soak.c): scenes from GSL's MT19937, the invariants checked
# with the engine's separating-axis test (engine/src/interference.h), each run in a child process.
target_sources(polydyn_validation PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/soak.c)
target_include_directories(polydyn_validation PRIVATE ${PROJECT_SOURCE_DIR}/engine/src)
