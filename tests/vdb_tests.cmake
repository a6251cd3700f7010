# The OpenVDB reader and its resampling. The .vdb files are not in the
# repository: make_test_vdbs writes them into vdb_data/ at test time (the
# vdb_generate test, a fixture that every other vdb test requires).

set(VDB_DATA ${CMAKE_CURRENT_BINARY_DIR}/vdb_data)

add_executable(make_test_vdbs ${CMAKE_CURRENT_SOURCE_DIR}/make_test_vdbs.cpp)
target_link_libraries(make_test_vdbs PRIVATE veil_openvdb veil_warnings)
add_test(NAME vdb_generate COMMAND make_test_vdbs ${VDB_DATA})
set_tests_properties(vdb_generate PROPERTIES FIXTURES_SETUP vdb_data LABELS unit)

# test_vdb DATA CASE: one ctest per case (tests/io/test_vdb.c).
add_executable(test_vdb ${CMAKE_CURRENT_SOURCE_DIR}/test_vdb.c ${CMAKE_CURRENT_SOURCE_DIR}/check.c)
target_link_libraries(test_vdb PRIVATE veil veil_fp veil_warnings)
function(veil_vdb_case name labels)
  add_test(NAME vdb_${name} COMMAND test_vdb ${VDB_DATA} ${name})
  set_tests_properties(vdb_${name} PROPERTIES FIXTURES_REQUIRED vdb_data LABELS "${labels}")
endfunction()
veil_vdb_case(open unit)
veil_vdb_case(select unit)
veil_vdb_case(level_set unit)
veil_vdb_case(types unit)
veil_vdb_case(bad_files unit)
# OpenVDB 10.0 leaks a node when a truncated file throws while its tree is
# read (RootNode allocates a child, whose read throws, before linking it);
# only this test reads one, so only it ignores leaks allocated in OpenVDB
# under VEIL_SANITIZE.
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/vdb_lsan.supp "leak:libopenvdb.so\n")
set_tests_properties(vdb_bad_files PROPERTIES
  ENVIRONMENT "LSAN_OPTIONS=suppressions=${CMAKE_CURRENT_BINARY_DIR}/vdb_lsan.supp")
veil_vdb_case(empty unit)
veil_vdb_case(transform unit)
veil_vdb_case(threads unit)
veil_vdb_case(fast_path "unit;accuracy")
veil_vdb_case(mass "unit;accuracy")
veil_vdb_case(rotated "unit;accuracy")
veil_vdb_case(limits unit)
# a scene's VDB source: veil_scene_volume_open with err == NULL on a missing
# and a corrupt file; veil_scene_volume_key is the file's identity, not its bytes
veil_vdb_case(scene_volume unit)
# Importing as production makes them (tests/volume/test_vdb_import.c): native
# resolution (a VDB without max_resolution keeps its voxels, values copied),
# NanoVDB and half-float files read exactly, the resampling filter by direction.
add_executable(test_vdb_import ${CMAKE_CURRENT_SOURCE_DIR}/test_vdb_import.c ${CMAKE_CURRENT_SOURCE_DIR}/check.c)
target_link_libraries(test_vdb_import PRIVATE veil veil_fp veil_warnings)
foreach(case native nanovdb filters)
  add_test(NAME vdb_${case} COMMAND test_vdb_import ${VDB_DATA} ${case})
  set_tests_properties(vdb_${case} PROPERTIES FIXTURES_REQUIRED vdb_data LABELS "unit;accuracy")
endforeach()

# Trees checked before OpenVDB reads them (tests/io/test_vdb_trees.c): every
# grid type under every compression reads; absurd claims inside a tree are
# refused by the check.
add_executable(test_vdb_trees ${CMAKE_CURRENT_SOURCE_DIR}/test_vdb_trees.c ${CMAKE_CURRENT_SOURCE_DIR}/check.c)
target_link_libraries(test_vdb_trees PRIVATE veil veil_fp veil_warnings)
foreach(case types corrupt)
  add_test(NAME vdb_trees_${case} COMMAND test_vdb_trees ${VDB_DATA} ${case})
  set_tests_properties(vdb_trees_${case} PROPERTIES FIXTURES_REQUIRED vdb_data LABELS "unit;bad_input")
endforeach()

# Truncated files fail fast and small, naming the file (tests/io/vdb_truncated.sh).
add_test(NAME vdb_truncated COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/vdb_truncated.sh $<TARGET_FILE:veil_cli>
                                   ${VDB_DATA}/fog_sphere.vdb)
set_tests_properties(vdb_truncated PROPERTIES FIXTURES_REQUIRED vdb_data LABELS "gpu;bad_input")

# The fuzz corpus (tests/fuzz/corpus/: seeds and the inputs fuzzing found) as
# regression inputs of every build (tests/fuzz/fuzz_corpus.sh).
add_test(NAME fuzz_corpus COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/fuzz_corpus.sh $<TARGET_FILE:veil_cli>
                                 ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus)
set_tests_properties(fuzz_corpus PROPERTIES LABELS "bad_input")

# The sparse volume (tests/volume/test_sparse.c): the 4096^3 puffs file against its crop.
add_executable(test_sparse ${CMAKE_CURRENT_SOURCE_DIR}/test_sparse.c ${CMAKE_CURRENT_SOURCE_DIR}/check.c)
target_link_libraries(test_sparse PRIVATE veil veil_fp veil_warnings)
add_test(NAME sparse_structure COMMAND test_sparse ${VDB_DATA} structure)
set_tests_properties(sparse_structure PROPERTIES FIXTURES_REQUIRED vdb_data LABELS "unit;accuracy")
foreach(case depth render emission)
  add_test(NAME sparse_${case} COMMAND test_sparse ${VDB_DATA} ${case})
  set_tests_properties(sparse_${case} PROPERTIES FIXTURES_REQUIRED vdb_data LABELS "gpu;accuracy" SKIP_RETURN_CODE 77)
endforeach()

# `veil info` (tests/cli/vdb_bad.sh VEIL EXPECTED_EXIT EXPECTED_TEXT ARGS...).
function(veil_vdb_cli name rc text)
  add_test(NAME vdb_cli_${name}
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/vdb_bad.sh $<TARGET_FILE:veil_cli> ${rc} "${text}" ${ARGN})
  set_tests_properties(vdb_cli_${name} PROPERTIES FIXTURES_REQUIRED vdb_data LABELS "cli;unit")
endfunction()
veil_vdb_cli(info_table 0 "density" info ${VDB_DATA}/offset_scaled.vdb)
# render says which grids of a file it did not read (and at which resolution it read the one it did)
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/two_grids_scene.json
  "{\"camera\": {\"position\": [0, 0, 3], \"look_at\": [0, 0, 0], \"width\": 16, \"height\": 12},
    \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": [{\"type\": \"vdb\", \"file\": \"${VDB_DATA}/two_grids.vdb\"}]}}\n")
veil_vdb_cli(render_unread 0 "values copied; not read: temperature (float)" render
             ${CMAKE_CURRENT_BINARY_DIR}/two_grids_scene.json -o ${CMAKE_CURRENT_BINARY_DIR}/two_grids_out.exr --stats)
veil_vdb_cli(info_table_count 0 "4096" info ${VDB_DATA}/offset_scaled.vdb)
# what render will do with a grid: copy it (axis-aligned cubes) or resample it (rotated)
veil_vdb_cli(info_native 0 "rendering native: axis-aligned 0.25 m cubes, values copied" info ${VDB_DATA}/offset_scaled.vdb)
veil_vdb_cli(info_nanovdb 0 "density fog volume float 4096 0.25" info ${VDB_DATA}/offset_scaled.nvdb)
veil_vdb_cli(info_sparse 0 "rendering sparse: axis-aligned 0.05 m cubes, a box of 6.88e+10 voxels" info ${VDB_DATA}/sparse_puffs.vdb)
veil_vdb_cli(info_rotated 0 "rendering resampled at its smallest voxel edge" info ${VDB_DATA}/rotated.vdb)
veil_vdb_cli(info_json 0 "\"name\": \"temperature\"" info ${VDB_DATA}/two_grids.vdb --json)
veil_vdb_cli(info_json_count 0 "\"active_voxels\": 5," info ${VDB_DATA}/two_grids.vdb --json)
veil_vdb_cli(info_garbage 1 "garbage.vdb: cannot read the OpenVDB file" info ${VDB_DATA}/garbage.vdb)
veil_vdb_cli(info_missing 1 "does_not_exist.vdb: cannot open: No such file or directory"
             info ${VDB_DATA}/does_not_exist.vdb)
veil_vdb_cli(info_usage 2 "info: missing FILE.vdb" info)

# A sparse volume asked for where there cannot be one (a rotated grid): exit 1
# naming the field and why, nothing written (tests/support/bad_input.sh).
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/bad_sparse_rotated.json
  "{\"camera\": {\"position\": [0, 0, 3], \"look_at\": [0, 0, 0], \"width\": 8, \"height\": 6},
    \"medium\": {\"sigma_s\": [1, 1, 1], \"representation\": \"sparse\",
      \"sources\": [{\"type\": \"vdb\", \"file\": \"${VDB_DATA}/rotated.vdb\"}]}}\n")
add_test(NAME bad_input_sparse_rotated
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/bad_input.sh $<TARGET_FILE:veil_cli>
                 ${CMAKE_CURRENT_BINARY_DIR}/bad_sparse_rotated.json
                 "medium.representation: \"sparse\" is not possible here: ${VDB_DATA}/rotated.vdb: its voxels are rotated or not cubes")
set_tests_properties(bad_input_sparse_rotated PROPERTIES FIXTURES_REQUIRED vdb_data LABELS bad_input)
# The 4096^3 puffs render sparse by themselves and say so, with the memory.
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/sparse_puffs_scene.json
  "{\"camera\": {\"position\": [100, 100, -8], \"look_at\": [100, 100, 0], \"width\": 16, \"height\": 12},
    \"medium\": {\"sigma_s\": [5, 5, 5], \"sources\": [{\"type\": \"vdb\", \"file\": \"${VDB_DATA}/sparse_puffs.vdb\"}]},
    \"lights\": [{\"type\": \"directional\", \"direction\": [0, -1, 0], \"irradiance\": [1, 1, 1]}]}\n")
veil_vdb_cli(render_sparse 0 "bricks kept of 135005697 (513x513x513)" render
             ${CMAKE_CURRENT_BINARY_DIR}/sparse_puffs_scene.json -o ${CMAKE_CURRENT_BINARY_DIR}/sparse_puffs.exr --stats)
set_tests_properties(vdb_cli_render_sparse PROPERTIES LABELS "cli;gpu")

# Emission (a vdb source's "emission" grid): march and reference against the
# closed form of an emissive absorbing slab.
add_executable(test_emission ${CMAKE_CURRENT_SOURCE_DIR}/test_emission.c ${CMAKE_CURRENT_SOURCE_DIR}/check.c)
target_link_libraries(test_emission PRIVATE veil veil_fp veil_warnings)
add_test(NAME test_emission COMMAND test_emission ${VDB_DATA})
set_tests_properties(test_emission PROPERTIES FIXTURES_REQUIRED vdb_data LABELS "gpu;accuracy" SKIP_RETURN_CODE 77)

# The emission lights its medium: 8 lights from the slab's emission (its 4000 voxels split k-d) join the scene's.
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/emission_lights_scene.json
  "{\"camera\": {\"position\": [0.95, 0.95, 6], \"look_at\": [0.95, 0.95, 0], \"width\": 16, \"height\": 12},
    \"medium\": {\"sigma_a\": [1, 1, 1], \"sigma_s\": [3, 3, 3], \"sources\": [{\"type\": \"vdb\",
      \"file\": \"${VDB_DATA}/emissive_slab.vdb\", \"emission\": {\"grid\": \"heat\"}}]},
    \"lights\": [{\"type\": \"directional\", \"direction\": [0, 0, -1], \"irradiance\": [1, 1, 1]}]}\n")
veil_vdb_cli(render_emission_lights 0 "1 of 1 lights (+8 from the emission)" render
             ${CMAKE_CURRENT_BINARY_DIR}/emission_lights_scene.json -o ${CMAKE_CURRENT_BINARY_DIR}/emission_lights.exr --stats)
set_tests_properties(vdb_cli_render_emission_lights PROPERTIES LABELS "cli;gpu")

# A vdb source's emission or temperature grid that the file lacks: exit 1 naming
# the field and the file's grids, nothing written (tests/support/bad_input.sh).
foreach(field emission temperature)
  file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/bad_${field}_grid.json
    "{\"camera\": {\"position\": [0, 0, 3], \"look_at\": [0, 0, 0], \"width\": 8, \"height\": 6},
      \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": [{\"type\": \"vdb\",
        \"file\": \"${VDB_DATA}/emissive_slab.vdb\", \"${field}\": {\"grid\": \"nope\"}}]}}\n")
  add_test(NAME bad_input_${field}_grid
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/bad_input.sh $<TARGET_FILE:veil_cli>
                   ${CMAKE_CURRENT_BINARY_DIR}/bad_${field}_grid.json
                   "medium.sources[0].${field}.grid: ${VDB_DATA}/emissive_slab.vdb: no grid named 'nope'")
  set_tests_properties(bad_input_${field}_grid PROPERTIES FIXTURES_REQUIRED vdb_data LABELS bad_input)
endforeach()
# An animated source: one VDB a frame through veil turntable (tests/cli/turntable_sequence.sh).
add_test(NAME cli_turntable_sequence
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/turntable_sequence.sh $<TARGET_FILE:veil_cli> ${VDB_DATA})
set_tests_properties(cli_turntable_sequence PROPERTIES FIXTURES_REQUIRED vdb_data LABELS "gpu;cli" SKIP_RETURN_CODE 77)
