/* libFuzzer target: the EXR reader (io/image.h, OpenEXRCore). */
#include "fuzz_common.h"
#include "io/image.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const char* path = fuzz_file(data, size, "f.exr");
    int w = 0, h = 0;
    float* rgba = NULL;
    veil_error err = {0};
    if (veil_read_exr(path, &w, &h, &rgba, &err) == VEIL_OK) {
        if (w < 1 || h < 1 || !rgba) abort();
    } else if (!err.msg[0]) {
        abort();
    }
    free(rgba);
    return 0;
}
