# What the user is told, checked against what the code does (label cli; no GPU).
#   slurm_script_logs  scripts/slurm-turntable.sh writes the jobs' logs to
#                      LOGS, or logs/ beside the frames, never to the folder
#                      it runs from (a stand-in sbatch; the real Slurm: ctest
#                      farm_slurm_turntable, label farm)
add_test(NAME slurm_script_logs
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/slurm_script_test.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(slurm_script_logs PROPERTIES LABELS cli)
