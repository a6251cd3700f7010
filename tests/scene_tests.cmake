# Scene parser: unit test, and one CLI test per bad scene file.

veil_test(test_scene SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_scene.c LABELS unit)

# bad_input_<stem>: `veil render SCENE` must exit 1, print EXPECTED on stderr
# and write no file (tests/support/bad_input.sh).
function(veil_bad_input stem scene expected)
  add_test(NAME bad_input_${stem}
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/bad_input.sh $<TARGET_FILE:veil_cli> ${scene} "${expected}")
  set_tests_properties(bad_input_${stem} PROPERTIES LABELS bad_input SKIP_RETURN_CODE 77)
endfunction()

set(BAD ${CMAKE_CURRENT_SOURCE_DIR}/data/bad)
veil_bad_input(syntax_error ${BAD}/syntax_error.json "syntax_error.json:6:3: JSON syntax error near")
veil_bad_input(trailing_content ${BAD}/trailing_content.json
               "trailing_content.json:5:1: JSON syntax error near '}': unexpected content after the JSON value")
veil_bad_input(empty ${BAD}/empty.json "empty.json:1:1: JSON syntax error: unexpected end of input")
veil_bad_input(not_an_object ${BAD}/not_an_object.json "expected a JSON object at the top level")
veil_bad_input(wrong_type ${BAD}/wrong_type.json
               "lights[1].intensity: expected an array of 3 numbers, each in [0, 1e20] (scene/limits.h), got a string")
veil_bad_input(unknown_key ${BAD}/unknown_key.json
               "camera.fov: unknown key (expected one of: position, look_at, up, fov_y_deg, width, height)")
veil_bad_input(missing_field ${BAD}/missing_field.json
               "camera.position: missing required field (an array of 3 numbers, each in [-1e15, 1e15] (m: scene/limits.h))")
veil_bad_input(negative_resolution ${BAD}/negative_resolution.json
               "medium.max_resolution: expected an integer in [2, 2048], got -16 (negative and zero values are not allowed)")
veil_bad_input(bad_phase_type ${BAD}/bad_phase_type.json "medium.phase.type: expected one of")
veil_bad_input(bad_quality ${BAD}/bad_quality.json "bad_quality.json: quality: expected one of \"draft\", \"default\", \"high\", \"max\", got a string (\"best\")")
veil_bad_input(g_out_of_range ${BAD}/g_out_of_range.json "medium.phase.g: expected a number in (-1, 1), got 1.5")
veil_bad_input(zero_direction ${BAD}/zero_direction.json "lights[0].direction: expected a non-zero vector")
veil_bad_input(bad_sharpness ${BAD}/bad_sharpness.json
               "medium.sources[0].particles[1].sharpness: expected a number >= 1e-29 (its cut-off radius within 1e15 m: scene/limits.h), got 0")
veil_bad_input(bad_seed ${BAD}/bad_seed.json "medium.sources[0].seed: expected an integer in [0, 2^53), got 1.5")
veil_bad_input(camera_on_target ${BAD}/camera_on_target.json "camera.look_at: must differ from camera.position")
veil_bad_input(too_many_lights ${BAD}/too_many_lights.json "too_many_lights.json: lights: too many elements (17, at most 16)")
# 2048^3 voxels and 16 lights: 672 GiB of textures, over any machine's budget;
# refused with the numbers before anything is allocated.
veil_bad_input(volume_too_large ${BAD}/volume_too_large.json
               "volume_too_large.json: a 2048x2048x2048 extinction volume with 16 lights needs")
veil_bad_input(fog_negative_falloff ${BAD}/fog_negative_falloff.json
               "fog_negative_falloff.json: medium.sources[0].falloff: expected a number >= 0, got -1")
veil_bad_input(fog_zero_direction ${BAD}/fog_zero_direction.json
               "fog_zero_direction.json: medium.sources[0].direction: expected a non-zero vector")
# a relative VDB path resolves against the scene's folder, and the message shows where it looked
veil_bad_input(vdb_missing_file ${BAD}/vdb_missing_file.json
               "vdb_missing_file.json: medium.sources[0].file: cannot open '${BAD}/no_such_smoke.vdb'")
veil_bad_input(missing_file ${BAD}/does_not_exist.json "does_not_exist.json: cannot open: No such file or directory")
veil_bad_input(directory ${BAD} "bad: cannot read: Is a directory")
veil_bad_input(spot_inner_ge_outer ${BAD}/spot_inner_ge_outer.json
               "spot_inner_ge_outer.json: lights[1].inner_angle_deg: expected a number of degrees in [0, outer_angle_deg) = [0, 25), got 40")
veil_bad_input(spot_missing_outer ${BAD}/spot_missing_outer.json
               "spot_missing_outer.json: lights[0].outer_angle_deg: missing required field (a number of degrees in (0, 180])")
# multiple_scattering: every field named in its message, with what was expected
veil_bad_input(ms_bad_filter ${BAD}/ms_bad_filter.json
               "multiple_scattering.filter: expected one of \"2x2\", \"4x4\", \"6x6\", got a string (\"5x5\")")
veil_bad_input(ms_bad_weights ${BAD}/ms_bad_weights.json
               "multiple_scattering.weights: expected an array of 2 numbers >= 0")
veil_bad_input(ms_bad_octaves ${BAD}/ms_bad_octaves.json
               "multiple_scattering.octaves: expected an integer in [1, 16], got 0")
veil_bad_input(ms_bad_gate ${BAD}/ms_bad_gate.json
               "multiple_scattering.octave_gate: expected one of \"legs\", \"escape\", got a string (\"both\")")
veil_bad_input(ms_bad_ramp ${BAD}/ms_bad_ramp.json
               "multiple_scattering.separation_density_width: expected at most separation_density (1)")
veil_bad_input(ms_not_bool ${BAD}/ms_not_bool.json "multiple_scattering.screen_space: expected true or false, got 1")
