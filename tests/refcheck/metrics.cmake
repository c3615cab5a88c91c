# The comparison metrics and `polydyn compare`.
pd_add_test(test_compare ${CMAKE_CURRENT_SOURCE_DIR}/test_compare.c)
target_link_libraries(test_compare PRIVATE polydyn_refcheck)
add_test(NAME test_compare_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_compare_cli.sh $<TARGET_FILE:polydyn> ${PROJECT_SOURCE_DIR})
add_test(NAME test_sweep_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_sweep_cli.sh $<TARGET_FILE:polydyn> ${PROJECT_SOURCE_DIR})
pd_test_labels(unit test_compare)
pd_test_labels(cli test_compare_cli test_sweep_cli)
