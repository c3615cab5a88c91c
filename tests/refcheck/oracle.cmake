# The libccd interference oracle: unit and fixed-seed property tests, and the `polydyn oracle` command.
pd_add_test(test_oracle test_oracle.c)
target_link_libraries(test_oracle PRIVATE polydyn_refcheck)
add_test(NAME test_oracle_cli
         COMMAND bash ${PROJECT_SOURCE_DIR}/tests/cli/test_oracle_cli.sh $<TARGET_FILE:polydyn> ${PROJECT_SOURCE_DIR})
# 10 000 random pairs near touching, seed 1: no verdict disagreement with libccd's GJK outside the touching
# band (exit status 0; 1 would mean a disagreement outside it).
add_test(NAME test_oracle_random_10000_seed_1
         COMMAND $<TARGET_FILE:polydyn> oracle --random 10000 --seed 1
                 --out ${CMAKE_CURRENT_BINARY_DIR}/oracle-random-10000-seed-1.csv)
pd_test_labels(unit test_oracle test_oracle_random_10000_seed_1)
pd_test_labels(cli test_oracle_cli)
pd_test_labels(slow test_oracle_random_10000_seed_1)
