# Checks on the sources and the built objects rather than on behaviour
# (scripts/check-*.sh; each says what it catches and which past defect).
#   check_headers    every library header compiles alone, also in the
#                    branch non-GNU compilers take, without redundant
#                    declarations (io/json_read.h declared veil__read_file
#                    twice there)
#   check_dead_code  every function libveil.a defines has a caller
#                    (veil_rbf_density and veil_pt_density had none); reads
#                    the objects of every target, so it runs after a full build
#   check_one_rng    SplitMix64's constants appear in core/rng.h only (the
#                    generator was once written four times)
add_test(NAME check_headers
  COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/check-headers.sh ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}
          ${CMAKE_C_COMPILER})
add_test(NAME check_dead_code
  COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/check-dead-code.sh ${PROJECT_BINARY_DIR} ${PROJECT_SOURCE_DIR}
          ${CMAKE_NM} ${CMAKE_C_COMPILER} $<TARGET_FILE:veil>)
add_test(NAME check_one_rng COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/check-one-rng.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(check_headers check_dead_code check_one_rng PROPERTIES LABELS unit)
