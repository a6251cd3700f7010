# The installed tree (tests/api/install_example.sh): cmake --install into a
# temporary prefix, examples/ built against it through the CMake package and
# through pkg-config, both run on the demo scene.
add_test(NAME install_example
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/install_example.sh ${PROJECT_BINARY_DIR} ${PROJECT_SOURCE_DIR})
set(VEIL_INSTALL_TEST_ENV "CMAKE=${CMAKE_COMMAND}" "CC=${CMAKE_C_COMPILER}")
if(VEIL_SANITIZE)
  # a sanitized libveil.so needs its consumer built with the same runtime
  list(APPEND VEIL_INSTALL_TEST_ENV "VEIL_EXAMPLE_CFLAGS=-fsanitize=address,undefined")
endif()
set_tests_properties(install_example PROPERTIES LABELS "install;cli" SKIP_RETURN_CODE 77
                     ENVIRONMENT "${VEIL_INSTALL_TEST_ENV}")

# The public API (include/veil.h) itself: NULL arguments, bad descriptions,
# channels, stage reports, a turntable's reuse, the writers.
veil_test(test_api SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_api.c LABELS gpu
          ARGS ${PROJECT_SOURCE_DIR}/data/scenes/demo.json)
