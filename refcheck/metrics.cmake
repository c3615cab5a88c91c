# Trajectories in memory and the comparison metrics of `polydyn compare` (refcheck/compare.c), what it shows
# over time, its impacts and the chaos verdict (refcheck/compare_detail.c); the
# penetration metric uses the engine's separating-axis test (engine/src/interference.h).
target_sources(polydyn_refcheck PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/compare.c
                                        ${CMAKE_CURRENT_SOURCE_DIR}/compare_detail.c)
target_include_directories(polydyn_refcheck PRIVATE ${PROJECT_SOURCE_DIR}/engine/src)
