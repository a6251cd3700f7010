# veil_embed_shaders(OUT_VAR file...): for each file, a custom command that
# turns it into build/shaders/<name>.c holding
#   const char veil_shader_<ident>[] = { ... , 0 };
# where <ident> is the file name with every non-alphanumeric replaced by '_'.
set(VEIL_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/embed_one.cmake)
function(veil_embed_shaders out_var)
  set(outputs)
  foreach(src IN LISTS ARGN)
    get_filename_component(name ${src} NAME)
    string(MAKE_C_IDENTIFIER ${name} ident)
    set(out ${CMAKE_CURRENT_BINARY_DIR}/shaders/${ident}.c)
    add_custom_command(
      OUTPUT ${out}
      COMMAND ${CMAKE_COMMAND} -DIN=${CMAKE_CURRENT_SOURCE_DIR}/${src} -DOUT=${out} -DIDENT=${ident}
              -P ${VEIL_EMBED_SCRIPT}
      DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${src} ${VEIL_EMBED_SCRIPT}
      COMMENT "Embedding shader ${src}")
    list(APPEND outputs ${out})
  endforeach()
  set(${out_var} ${outputs} PARENT_SCOPE)
endfunction()
