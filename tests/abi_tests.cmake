# The ABI is include/ (include/veil.h, "ABI" and "Descriptions grow").
#   check_exports           libveil.so exports exactly what include/ declares
#                           with VEIL_API (tests/check_exports.sh); before
#                           hidden visibility it listed 7387 symbols: veil's
#                           internal functions and data, OpenVDB's template
#                           code
#   check_exports_selftest  that check fails on a header missing a
#                           declaration, an unmarked declaration, and stray or
#                           missing symbols
#   test_abi                a program linked against libveil.so alone: the
#                           version macros equal the library's answers and
#                           CMake's project version; bad description sizes
#                           are refused before any GL work
#   test_abi_render         the same program rendering: size 0, the
#                           initializer and a padded description agree; bad
#                           sizes are refused
#   test_desc_size          the growing rule on a made-up two-layout
#                           description (frame/desc_size.h)
set(VEIL_PUBLIC_HEADERS ${PROJECT_SOURCE_DIR}/include/veil.h ${PROJECT_SOURCE_DIR}/include/veil/result.h)
add_test(NAME check_exports
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/check_exports.sh ${CMAKE_C_COMPILER} ${CMAKE_NM}
                 $<TARGET_FILE:veil_shared> ${VEIL_PUBLIC_HEADERS})
add_test(NAME check_exports_selftest
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/check_exports_selftest.sh ${CMAKE_C_COMPILER} ${CMAKE_NM}
                 $<TARGET_FILE:veil_shared> ${PROJECT_SOURCE_DIR}/include)
set_tests_properties(check_exports check_exports_selftest PROPERTIES LABELS unit)

add_executable(test_abi ${CMAKE_CURRENT_SOURCE_DIR}/test_abi.c)
target_link_libraries(test_abi PRIVATE veil_shared veil_warnings ${CMAKE_DL_LIBS})
target_compile_definitions(test_abi PRIVATE VEIL_TEST_CMAKE_VERSION="${PROJECT_VERSION}")
add_test(NAME test_abi COMMAND test_abi)
add_test(NAME test_abi_render COMMAND test_abi render ${PROJECT_SOURCE_DIR}/data/scenes/demo.json)
set_tests_properties(test_abi PROPERTIES LABELS unit)
set_tests_properties(test_abi_render PROPERTIES LABELS gpu SKIP_RETURN_CODE 77)

veil_test(test_desc_size SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_desc_size.c LABELS unit)
