# The planar drops in the cube-toss machinery, on synthetic drops (no data needed).
pd_add_test(test_planar_drops ${CMAKE_CURRENT_LIST_DIR}/test_planar_drops.c)
target_link_libraries(test_planar_drops PRIVATE polydyn_validation)
# polydyn cubetoss on planar drops end to end (synthetic drops; three real ones when ../shared is there).
add_test(NAME test_planar_drops_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_planar_drops_cli.sh $<TARGET_FILE:polydyn> ${PROJECT_SOURCE_DIR})
set_tests_properties(test_planar_drops_cli PROPERTIES SKIP_RETURN_CODE 77)
set_tests_properties(test_planar_drops PROPERTIES LABELS physics)
set_tests_properties(test_planar_drops_cli PROPERTIES LABELS cli)
