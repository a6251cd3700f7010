# `veil compare` (reference/compare.c, cli/compare.c): the metrics against
# values worked out independently, the heatmap's colour map and PNG writer,
# and the command end to end (tests/cli/compare_cli.sh, on EXRs that
# make_compare_exrs writes at test time).
veil_test(test_compare SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_compare.c LABELS unit)
target_link_libraries(test_compare PRIVATE PkgConfig::PNG)

add_executable(make_compare_exrs ${CMAKE_CURRENT_SOURCE_DIR}/make_compare_exrs.c)
target_link_libraries(make_compare_exrs PRIVATE veil veil_fp veil_warnings)
add_test(NAME compare_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/compare_cli.sh $<TARGET_FILE:veil_cli>
                 $<TARGET_FILE:make_compare_exrs>)
set_tests_properties(compare_cli PROPERTIES LABELS "cli;unit")
