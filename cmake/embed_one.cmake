# cmake -DIN=file -DOUT=file.c -DIDENT=name -P embed_one.cmake
file(READ ${IN} hex HEX)
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
get_filename_component(dir ${OUT} DIRECTORY)
file(MAKE_DIRECTORY ${dir})
file(WRITE ${OUT} "/* generated from ${IN}; do not edit */\nconst char veil_shader_${IDENT}[] = {${bytes}0x00};\n")
