# Image files (io/exr.c, io/png.c): EXR round trips, foreign EXR inputs (half,
# tiled, extra channels), failure cleanup, the PNG preview and its tone curve.
# The test also calls OpenEXRCore and libpng directly (to inspect the files it
# gets and to make inputs veil never writes), so it links them itself.
veil_test(test_image SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_image.c LABELS unit)
target_include_directories(test_image PRIVATE ${OPENEXR_INCLUDE_DIRS})
target_link_libraries(test_image PRIVATE PkgConfig::PNG ${OPENEXRCORE_LIB})
