# The random-scene soak (validation/soak.c): the checks at every accepted step catch what the samples miss, the
# first generator replays committed campaigns, the second draws plates. The CLI and CI's campaign:
# tests/cli/test_soak.sh.
pd_add_test(test_soak_checks ${CMAKE_CURRENT_LIST_DIR}/test_soak.c)
target_link_libraries(test_soak_checks PRIVATE polydyn_validation)
pd_test_labels(physics test_soak_checks)
# slow: it runs a committed failure of six bodies to its end islands off (about 10^5 accepted steps)
pd_test_labels(slow test_soak_checks)
