# Tests of the Bullet adapter (refcheck/bullet.cmake).
pd_add_test(test_bullet_adapter test_bullet_adapter.c)
target_link_libraries(test_bullet_adapter PRIVATE polydyn_refcheck)
pd_test_labels(physics test_bullet_adapter)
