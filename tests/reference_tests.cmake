# CPU ground truth for optical depth (reference/): exactness, closed forms,
# and convergence of the midpoint rule and of the voxelisation.
veil_test(test_reference SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_reference.c LABELS "unit;accuracy")
veil_test(test_closed_forms SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_closed_forms.c LABELS "unit;accuracy")
veil_test(test_fog_closed_form SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_fog_closed_form.c LABELS "unit;accuracy")
