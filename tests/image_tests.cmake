# Image files (io/exr.c, io/exr_read.c, io/png.c): EXR round trips, foreign EXR inputs (half,
# tiled, extra channels), failure cleanup, the PNG preview and its tone curve.
# The tests also call OpenEXRCore and libpng directly (to inspect the files
# they get and to make inputs veil never writes), so they link them themselves.
foreach(t test_exr test_png)
  veil_test(${t} SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/${t}.c LABELS unit)
  target_include_directories(${t} PRIVATE ${OPENEXR_INCLUDE_DIRS})
  target_link_libraries(${t} PRIVATE PkgConfig::PNG ${OPENEXRCORE_LIB})
endforeach()
