# The Bullet adapter (pd_bullet_adapter): Debian's libbullet-dev, double-precision build, behind a C++17 shim.
pkg_check_modules(BULLET REQUIRED IMPORTED_TARGET bullet-float64)
target_sources(polydyn_refcheck PRIVATE ${CMAKE_CURRENT_LIST_DIR}/bullet_adapter.c ${CMAKE_CURRENT_LIST_DIR}/bullet_shim.cpp)
target_compile_features(polydyn_refcheck PRIVATE cxx_std_17)
target_compile_definitions(polydyn_refcheck PRIVATE PD_HAVE_BULLET_ADAPTER)
target_link_libraries(polydyn_refcheck PRIVATE PkgConfig::BULLET)
