# Batch runs over worker processes (refcheck/batch.c); over MPI ranks: tests/cli/test_batch.sh.
pd_add_test(test_batch ${CMAKE_CURRENT_SOURCE_DIR}/test_batch.c)
target_link_libraries(test_batch PRIVATE polydyn_refcheck)
pd_test_labels(unit test_batch)
