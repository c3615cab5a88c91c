# The cube-toss validation (`polydyn cubetoss`): library tests on synthetic tosses, tests on the real data
# (skipped, exit 77, when ../shared/data/cube-toss/ is absent) and the command end to end.
pd_add_test(test_cubetoss ${CMAKE_CURRENT_SOURCE_DIR}/test_cubetoss.c)
target_link_libraries(test_cubetoss PRIVATE polydyn_validation)
pd_add_test(test_cubetoss_data ${CMAKE_CURRENT_SOURCE_DIR}/test_cubetoss_data.c)
target_link_libraries(test_cubetoss_data PRIVATE polydyn_validation)
set_tests_properties(test_cubetoss_data PROPERTIES SKIP_RETURN_CODE 77)
add_test(NAME test_cubetoss_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_cubetoss_cli.sh $<TARGET_FILE:polydyn> ${PROJECT_SOURCE_DIR})
set_tests_properties(test_cubetoss_cli PROPERTIES SKIP_RETURN_CODE 77)
pd_test_labels(unit test_cubetoss)
pd_test_labels(physics test_cubetoss_data)
pd_test_labels(cli test_cubetoss_cli)
