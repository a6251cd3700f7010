veil_test(test_rbf SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_rbf.c LABELS unit)
veil_test(test_propagate_homogeneous SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_propagate_homogeneous.c LABELS unit)
veil_test(test_propagate_accuracy SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_propagate_accuracy.c LABELS "unit;accuracy")
veil_test(test_sun_space SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_sun_space.c LABELS "unit;accuracy")
veil_test(test_frames SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_frames.c LABELS unit)
# The layout's include rules (docs/architecture.md) hold on the tree, and
# the checker catches each kind of violation on trees made for the purpose.
add_test(NAME check_layout COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/check-layout.sh ${PROJECT_SOURCE_DIR})
add_test(NAME check_layout_selftest
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/check_layout_selftest.sh ${PROJECT_SOURCE_DIR}/scripts/check-layout.sh)
set_tests_properties(check_layout check_layout_selftest PROPERTIES LABELS unit)
# Premoze's spread width W (limits, Eq. 1), the level selection and the
# gathering filter against a direct convolution (render/spread.h's CPU parts).
veil_test(test_spread_width SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_spread_width.c LABELS unit)
# Blackbody radiance through the CIE curves to Rec.709 (volume/blackbody.h).
veil_test(test_blackbody SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_blackbody.c LABELS unit)
veil_test(test_signals SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_signals.c LABELS unit)
veil_test(test_emission_lights SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_emission_lights.c LABELS unit)
