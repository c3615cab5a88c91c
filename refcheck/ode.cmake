# The ODE adapter (refcheck/ode_adapter.c): Debian's libode-dev 0.16.2, double precision.
pkg_check_modules(ODE REQUIRED IMPORTED_TARGET ode)
target_sources(polydyn_refcheck PRIVATE ${CMAKE_CURRENT_LIST_DIR}/ode_adapter.c)
target_link_libraries(polydyn_refcheck PRIVATE PkgConfig::ODE)
target_compile_definitions(polydyn_refcheck PRIVATE PD_HAVE_ODE_ADAPTER)
