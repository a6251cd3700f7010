# What the user is told, checked against what the code does (label cli; no GPU).
#   cli_docs           the README's command block is the one description of the
#                      CLI: veil --help prints its usage lines, cli/main.c
#                      dispatches and names the same commands, and each cli/X.c
#                      parses exactly the options its line lists
#   cli_docs_selftest  the check fails, with a diff naming the change, on
#                      doctored copies of the README (a command or an option
#                      dropped, added or renamed)
#   slurm_script_logs  scripts/slurm-turntable.sh writes the jobs' logs to
#                      LOGS, or logs/ beside the frames, never to the folder
#                      it runs from (a stand-in sbatch; the real Slurm: ctest
#                      farm_slurm_turntable, label farm)
add_test(NAME cli_docs
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli_docs_test.sh $<TARGET_FILE:veil_cli> ${PROJECT_SOURCE_DIR}/README.md
          ${PROJECT_SOURCE_DIR})
add_test(NAME cli_docs_selftest
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli_docs_selftest.sh ${CMAKE_CURRENT_SOURCE_DIR}/cli_docs_test.sh
          $<TARGET_FILE:veil_cli> ${PROJECT_SOURCE_DIR})
add_test(NAME slurm_script_logs
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/slurm_script_test.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(cli_docs cli_docs_selftest slurm_script_logs PROPERTIES LABELS cli)
