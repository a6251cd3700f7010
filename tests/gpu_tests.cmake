veil_test(test_gpu_context SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_gpu_context.c LABELS gpu)
veil_test(test_inject_gpu SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_inject_gpu.c LABELS gpu)
veil_test(test_propagate_gpu SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_propagate_gpu.c LABELS gpu)
veil_test(test_sun_space_gpu SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_sun_space_gpu.c LABELS gpu)
veil_test(test_single_scatter SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_single_scatter.c LABELS "gpu;accuracy")

# End to end through the CLI: the demo scene at a small size, gpuinfo, usage.
# exr_stats (a test tool) checks the values of the files it writes.
add_executable(exr_stats ${CMAKE_CURRENT_SOURCE_DIR}/exr_stats.c)
target_include_directories(exr_stats PRIVATE ${OPENEXR_INCLUDE_DIRS})
target_link_libraries(exr_stats PRIVATE veil veil_fp veil_warnings PkgConfig::PNG ${OPENEXRCORE_LIB})
add_test(NAME cli_end_to_end
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli_end_to_end.sh $<TARGET_FILE:veil_cli>
          ${PROJECT_SOURCE_DIR}/data/scenes/demo.json $<TARGET_FILE:exr_stats>)
set_tests_properties(cli_end_to_end PROPERTIES LABELS "gpu;cli" SKIP_RETURN_CODE 77)
# Output paths (issue 12): never the input, never two outputs in one file, never
# an existing output lost when the PNG fails after the EXR (tests/cli/output_paths.sh).
add_test(NAME cli_output_paths
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/output_paths.sh $<TARGET_FILE:veil_cli>
          ${PROJECT_SOURCE_DIR}/data/scenes/height_fog.json)
set_tests_properties(cli_output_paths PROPERTIES LABELS "gpu;cli;bad_input" SKIP_RETURN_CODE 77)
# A status line on a terminal for the work under way, none in a pipe (tests/cli/progress_tty.sh).
add_test(NAME cli_progress_tty
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/progress_tty.sh $<TARGET_FILE:veil_cli>
          ${PROJECT_SOURCE_DIR}/data/scenes/rbf_fog.json)
set_tests_properties(cli_progress_tty PROPERTIES LABELS "gpu;cli" SKIP_RETURN_CODE 77)
# The march in bands of rows equals one dispatch, bit for bit (tests/render/test_march_bands.c).
veil_test(test_march_bands SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_march_bands.c LABELS gpu
          ARGS ${PROJECT_SOURCE_DIR}/data/scenes/rbf_fog.json)
veil_test(test_render_cache SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_render_cache.c LABELS gpu)
# The marcher against closed forms (airlight, a Gaussian's erf, slanted
# exponential fog) within step-error bounds derived in the test.
veil_test(test_marcher_closed_forms SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_marcher_closed_forms.c LABELS "gpu;accuracy")
# The image set's AOVs (T, P, single scattering, depth) against closed forms,
# and their named EXR channels.
veil_test(test_image_set SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_image_set.c LABELS "gpu;accuracy")
# veil render --explain: the plan of a turntable, without a GPU, agreeing
# with what --stats reports.
add_test(NAME cli_explain
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli_explain.sh $<TARGET_FILE:veil_cli> ${PROJECT_SOURCE_DIR}/data/scenes)
set_tests_properties(cli_explain PROPERTIES LABELS "gpu;cli" SKIP_RETURN_CODE 77)
# The screen-space spread (render/spread.h): a pure blur keeps energy, the
# MIP chains against the gathering filter, P = 0 spreads nothing.
veil_test(test_spread SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_spread.c LABELS "gpu;accuracy")
# veil fog's path: a frame behind homogeneous fog against closed forms.
veil_test(test_fog SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_fog.c LABELS "gpu;accuracy")
# veil fog end to end: good frames, and bad ones (no depth, NaN depth, size) refused.
add_executable(make_fog_frames ${CMAKE_CURRENT_SOURCE_DIR}/make_fog_frames.c)
target_link_libraries(make_fog_frames PRIVATE veil veil_fp veil_warnings)
add_test(NAME fog_cli
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/fog_cli.sh $<TARGET_FILE:veil_cli> $<TARGET_FILE:make_fog_frames>
          $<TARGET_FILE:exr_stats>)
set_tests_properties(fog_cli PROPERTIES LABELS "gpu;cli" SKIP_RETURN_CODE 77)
# The volumetric fields (render/diffusion.h): the octaves' escape field
# against its closed form, the diffusion fluence's convergence.
veil_test(test_diffusion SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_diffusion.c LABELS "gpu;accuracy")
# veil turntable: ranges, shards (byte-identical to one run), --skip-existing, usage errors.
add_test(NAME cli_turntable
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/turntable_cli.sh $<TARGET_FILE:veil_cli> ${PROJECT_SOURCE_DIR}/data/scenes/rbf_fog.json)
set_tests_properties(cli_turntable PROPERTIES LABELS "gpu;cli" SKIP_RETURN_CODE 77)
# A turntable on a one-node Slurm started by the test (tests/cli/farm_test.sh): label farm,
# not part of make test; make test-farm installs slurm-wlm and munge and runs it.
add_test(NAME farm_slurm_turntable
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/farm_test.sh $<TARGET_FILE:veil_cli> ${PROJECT_SOURCE_DIR}/data/scenes/rbf_fog.json
          ${PROJECT_SOURCE_DIR})
set_tests_properties(farm_slurm_turntable PROPERTIES LABELS farm SKIP_RETURN_CODE 77 TIMEOUT 600)
