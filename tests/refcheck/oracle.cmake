# The libccd interference oracle: unit and fixed-seed property tests, and the `polydyn oracle` command.
pd_add_test(test_oracle test_oracle.c)
target_link_libraries(test_oracle PRIVATE polydyn_refcheck)
add_test(NAME test_oracle_cli
         COMMAND bash ${PROJECT_SOURCE_DIR}/tests/cli/test_oracle_cli.sh $<TARGET_FILE:polydyn> ${PROJECT_SOURCE_DIR})
