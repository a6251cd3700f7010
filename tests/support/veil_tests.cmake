# The two ways a test is registered, shared by every folder under tests/.

# veil_test(NAME SOURCES f.c... LABELS l... [ARGS a...]): a C test program
# linked with the library and the harness (support/check.h), one ctest of
# the same name; exit 77 is a skip (no GL 4.5 context).
function(veil_test name)
  cmake_parse_arguments(T "" "" "SOURCES;LABELS;ARGS" ${ARGN})
  add_executable(${name} ${T_SOURCES})
  target_link_libraries(${name} PRIVATE veil_test_support veil veil_fp veil_warnings)
  add_test(NAME ${name} COMMAND ${name} ${T_ARGS})
  set_tests_properties(${name} PROPERTIES LABELS "${T_LABELS}" SKIP_RETURN_CODE 77)
endfunction()

# veil_bad_input(STEM SCENE EXPECTED): ctest bad_input_<STEM>, where
# `veil render SCENE` must exit 1, print EXPECTED on stderr and write no
# file (support/bad_input.sh).
function(veil_bad_input stem scene expected)
  add_test(NAME bad_input_${stem}
           COMMAND bash ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/bad_input.sh $<TARGET_FILE:veil_cli> ${scene} "${expected}")
  set_tests_properties(bad_input_${stem} PROPERTIES LABELS bad_input SKIP_RETURN_CODE 77)
endfunction()
