# The libccd interference oracle (docs/validation.md): Debian's libccd-dev, built in double.
pkg_check_modules(CCD REQUIRED IMPORTED_TARGET ccd)
target_sources(polydyn_refcheck PRIVATE ${CMAKE_CURRENT_LIST_DIR}/oracle.c ${CMAKE_CURRENT_LIST_DIR}/oracle_shapes.c
                                        ${CMAKE_CURRENT_LIST_DIR}/oracle_csv.c ${CMAKE_CURRENT_LIST_DIR}/oracle_timing.c)
# our side of the comparison is the engine's internal SAT (engine/src/interference.h)
target_include_directories(polydyn_refcheck PRIVATE ${PROJECT_SOURCE_DIR}/engine/src)
target_link_libraries(polydyn_refcheck PRIVATE PkgConfig::CCD m)
