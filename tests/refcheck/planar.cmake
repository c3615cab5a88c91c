# The planar constraint (scene `planar`) in the soft engine, ODE and Bullet: planarity to round-off, the
# Gedanken restitution and incline laws for a planar body, and the scene errors (the planar drops:
# tests/validation/planar_drops.cmake).
pd_add_test(test_planar ${CMAKE_CURRENT_LIST_DIR}/test_planar.c)
target_link_libraries(test_planar PRIVATE polydyn_refcheck)
set_tests_properties(test_planar PROPERTIES LABELS physics)
