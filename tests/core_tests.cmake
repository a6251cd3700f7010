veil_test(test_rbf SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_rbf.c LABELS unit)
veil_test(test_propagate_homogeneous SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_propagate_homogeneous.c LABELS unit)
veil_test(test_propagate_accuracy SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_propagate_accuracy.c LABELS "unit;accuracy")
