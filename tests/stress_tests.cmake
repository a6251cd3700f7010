# Stress: 500 seeded random extreme scenes (tests/frame/test_stress.c) through
# parse, inject, propagate and march on one renderer, the CPU optical-depth
# reference and the CPU path tracer: finite output, alpha in [0, 1], T
# non-increasing along rays, optical depths finite, >= 0 and monotone.
# About 20-40 s on llvmpipe with 2 cores.
veil_test(test_stress SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_stress.c LABELS "gpu;stress")
set_tests_properties(test_stress PROPERTIES TIMEOUT 600)
