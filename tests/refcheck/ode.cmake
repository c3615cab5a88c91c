# Tests of the ODE adapter (refcheck/ode_adapter.c).
pd_add_test(test_ode_adapter ${CMAKE_CURRENT_LIST_DIR}/test_ode_adapter.c)
target_link_libraries(test_ode_adapter PRIVATE polydyn_refcheck)
pd_test_labels(physics test_ode_adapter)
