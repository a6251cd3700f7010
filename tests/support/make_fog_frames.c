/* Writes the frames tests/cli/fog_cli.sh feeds to `veil fog`, into the folder
 * given (the scene fog_scene.json there is 32x24):
 *   good.exr     32x24, R, G, B = 2, 1, 0.5, Z = 5 (m)
 *   depthz.exr   the same with the depth in "depth.Z"
 *   sky.exr      the same with Z = +inf in the top half
 *   noz.exr      R, G, B only (no depth channel)
 *   nanz.exr     good with Z of pixel (7, 3) NaN
 *   negz.exr     good with Z of pixel (0, 0) -1
 *   small.exr    16x12 (not the scene camera's size)
 *   uintz.exr    R, G, B floats and Z as uint (a depth veil cannot read)
 *   negrgb.exr   good with G of pixel (5, 2) -0.25 (negative radiance)
 *   hugergb.exr  good with R of pixel (1, 1) 3e38 (fog over it would overflow) */
#include "io/image.h"
#include "support/exr_core.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 32, H = 24 };

static int write(const char* dir, const char* name, int w, int h, const char* zname, int mode)
{
    size_t n = (size_t)w * (size_t)h;
    float* planes = malloc(4 * n * sizeof *planes);
    if (!planes) return 1;
    const float rgb[3] = {2.0f, 1.0f, 0.5f};
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) planes[(size_t)c * n + i] = rgb[c];
        planes[3 * n + i] = 5.0f;
        if (mode == 1 && i < n / 2) planes[3 * n + i] = INFINITY;
    }
    if (mode == 2) planes[3 * n + 3 * (size_t)w + 7] = NAN;
    if (mode == 3) planes[3 * n] = -1.0f;
    if (mode == 4) planes[1 * n + 2 * (size_t)w + 5] = -0.25f;
    if (mode == 5) planes[(size_t)w + 1] = 3e38f;
    const char* names[4] = {"R", "G", "B", zname};
    const float* p[4] = {planes, planes + n, planes + 2 * n, planes + 3 * n};
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    veil_error err = {0};
    veil_result r = veil_write_exr_planes(path, w, h, zname ? 4 : 3, names, p, &err);
    free(planes);
    if (r != VEIL_OK) fprintf(stderr, "%s\n", err.msg);
    return r != VEIL_OK;
}

/* R, G, B as floats, Z as uint 5, through OpenEXRCore (veil writes no uint). */
static int write_uint_z(const char* dir)
{
    static float rgb[3][W * H];
    static uint32_t z[W * H];
    for (int i = 0; i < W * H; ++i) {
        rgb[0][i] = 2.0f, rgb[1][i] = 1.0f, rgb[2][i] = 0.5f;
        z[i] = 5;
    }
    const test_chan chans[4] = {{"R", EXR_PIXEL_FLOAT, rgb[0]}, {"G", EXR_PIXEL_FLOAT, rgb[1]},
                                {"B", EXR_PIXEL_FLOAT, rgb[2]}, {"Z", EXR_PIXEL_UINT, z}};
    exr_attr_box2i_t dw;
    dw.min.x = dw.min.y = 0;
    dw.max.x = W - 1;
    dw.max.y = H - 1;
    char path[4096];
    snprintf(path, sizeof path, "%s/uintz.exr", dir);
    return !core_write(path, EXR_COMPRESSION_NONE, dw, 0, chans, 4);
}

int main(int argc, char** argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_fog_frames DIR\n");
        return 2;
    }
    const char* d = argv[1];
    int bad = write(d, "good.exr", W, H, "Z", 0) | write(d, "depthz.exr", W, H, "depth.Z", 0) |
              write(d, "sky.exr", W, H, "Z", 1) | write(d, "noz.exr", W, H, NULL, 0) |
              write(d, "nanz.exr", W, H, "Z", 2) | write(d, "negz.exr", W, H, "Z", 3) |
              write(d, "small.exr", W / 2, H / 2, "Z", 0) | write(d, "negrgb.exr", W, H, "Z", 4) |
              write(d, "hugergb.exr", W, H, "Z", 5) |
              write_uint_z(d);
    return bad;
}
