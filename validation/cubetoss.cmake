# Validation against real cube tosses (`polydyn cubetoss`, validation/include/pdval/cubetoss.h): reading the
# data, one toss in each engine and its errors, the worker processes, and the Nelder–Mead fit (GSL, linked
# through the engine).
target_sources(polydyn_validation PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/cubetoss_data.c
  ${CMAKE_CURRENT_SOURCE_DIR}/cubetoss_sim.c
  ${CMAKE_CURRENT_SOURCE_DIR}/cubetoss_fit.c)
