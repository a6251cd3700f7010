# The reference path tracer (reference/pathtracer.h) against closed forms:
# Beer-Lambert, exponential fog, a Gaussian's erf line integral, the
# airlight of a point light (Sun et al. 2005), a white furnace, HG sampling
# (chi-square), determinism across thread counts.
veil_test(test_pathtracer SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_pathtracer.c LABELS "unit;accuracy")

# Equiangular sampling + MIS (distance sampling, chi-square, unbiasedness
# against quadrature and against distance sampling alone, variance), the
# fast exact optical depth, and the standard error of all-equal pixels.
veil_test(test_equiangular SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_equiangular.c LABELS "unit;accuracy")

# `veil reference` on the command line (no GPU needed).
add_test(NAME reference_cli
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/reference_cli.sh $<TARGET_FILE:veil_cli>
          ${PROJECT_SOURCE_DIR}/data/scenes/demo.json)
set_tests_properties(reference_cli PROPERTIES LABELS "cli")
