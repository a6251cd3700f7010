# Stress: 500 seeded random extreme scenes through parse, inject, propagate
# and march on one renderer (finite output, T non-increasing along rays,
# optical depths finite and >= 0). Runs on llvmpipe in well under a minute.
veil_test(test_stress SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_stress.c LABELS "gpu;stress")
set_tests_properties(test_stress PROPERTIES TIMEOUT 600)
