/* Writes the EXRs that tests/cli/compare_cli.sh compares, into the folder given:
 *   ref.exr      8x6, R = 0.5 + 0.01 x, G = 0.25 + 0.02 y, B = 0.1 + 0.01 (x + y), A = 1
 *   same.exr     a copy of ref
 *   scaled.exr   ref's RGB times 1.1 (A unchanged): every relative error 0.1
 *   one_off.exr  ref with R of pixel (3, 2) raised by 0.25
 *   alpha.exr    ref with A of pixel (0, 0) 0.75
 *   nan.exr      ref with B of pixel (5, 4) NaN
 *   small.exr    4x3 (a size mismatch)
 *   black.exr    8x6, RGB 0, A 1 (an all-black reference: its mean bias is undefined)
 *   ref_se.exr   ref with stderr.R, .G, .B = 0.02 x the value (as `veil reference` writes)
 *   ref_bound.exr ref_se with stderr.bound = 1 everywhere (every error a bound)
 *   ref_se_nan.exr, ref_se_neg.exr  ref_se with stderr.G of pixel (3, 2) NaN, stderr.B of (0, 1) -0.01
 *   ref_se_part.exr ref with stderr.R alone
 * The script knows these numbers; they are stated here once. */
#include "io/image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

enum { W = 8, H = 6 };

static float ref_value(int x, int y, int c)
{
    switch (c) {
    case 0: return 0.5f + 0.01f * (float)x;
    case 1: return 0.25f + 0.02f * (float)y;
    case 2: return 0.1f + 0.01f * (float)(x + y);
    default: return 1.0f;
    }
}

static int write(const char* dir, const char* name, int w, int h, const float* rgba)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    veil_error err = {0};
    if (veil_write_exr(path, w, h, rgba, &err) != VEIL_OK) {
        fprintf(stderr, "make_compare_exrs: %s\n", err.msg);
        return 0;
    }
    return 1;
}

int main(int argc, char** argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_compare_exrs DIR\n");
        return 2;
    }
    const char* dir = argv[1];
    float ref[W * H * 4], img[W * H * 4];
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int c = 0; c < 4; ++c) ref[(y * W + x) * 4 + c] = ref_value(x, y, c);
    int ok = write(dir, "ref.exr", W, H, ref) && write(dir, "same.exr", W, H, ref);

    for (int i = 0; i < W * H * 4; ++i) img[i] = (i % 4 == 3) ? ref[i] : (float)(1.1 * (double)ref[i]);
    ok = ok && write(dir, "scaled.exr", W, H, img);

    for (int i = 0; i < W * H * 4; ++i) img[i] = ref[i];
    img[(2 * W + 3) * 4 + 0] += 0.25f;
    ok = ok && write(dir, "one_off.exr", W, H, img);

    for (int i = 0; i < W * H * 4; ++i) img[i] = ref[i];
    img[3] = 0.75f;
    ok = ok && write(dir, "alpha.exr", W, H, img);

    for (int i = 0; i < W * H * 4; ++i) img[i] = ref[i];
    img[(4 * W + 5) * 4 + 2] = NAN;
    ok = ok && write(dir, "nan.exr", W, H, img);

    ok = ok && write(dir, "small.exr", 4, 3, ref);

    for (int i = 0; i < W * H * 4; ++i) img[i] = (i % 4 == 3) ? 1.0f : 0.0f;
    ok = ok && write(dir, "black.exr", W, H, img);

    /* the reference with standard errors, planes R G B A stderr.R/G/B (stderr.bound) */
    static float planes[8][W * H];
    for (int i = 0; i < W * H; ++i) {
        for (int c = 0; c < 4; ++c) planes[c][i] = ref[4 * i + c];
        for (int c = 0; c < 3; ++c) planes[4 + c][i] = 0.02f * ref[4 * i + c];
        planes[7][i] = 1.0f;
    }
    static const char* const names[8] = {"R", "G", "B", "A", "stderr.R", "stderr.G", "stderr.B", "stderr.bound"};
    const float* p[8];
    for (int c = 0; c < 8; ++c) p[c] = planes[c];
    veil_error err = {0};
    char path[4096];
    for (int k = 0; k < 2 && ok; ++k) {
        snprintf(path, sizeof path, "%s/%s", dir, k ? "ref_bound.exr" : "ref_se.exr");
        if (veil_write_exr_planes(path, W, H, k ? 8 : 7, names, p, &err) != VEIL_OK) {
            fprintf(stderr, "make_compare_exrs: %s\n", err.msg);
            ok = 0;
        }
    }
    /* bad standard errors: a NaN in stderr.G at (3, 2), a negative stderr.B at (0, 1), stderr.R alone */
    static const struct {
        const char* name;
        int plane, pixel, n;
        float value;
    } bad[3] = {{"ref_se_nan.exr", 5, 2 * W + 3, 7, NAN}, {"ref_se_neg.exr", 6, W, 7, -0.01f},
                {"ref_se_part.exr", 4, 0, 5, 0.02f}};
    for (int k = 0; k < 3 && ok; ++k) {
        const float keep = planes[bad[k].plane][bad[k].pixel];
        planes[bad[k].plane][bad[k].pixel] = bad[k].value;
        snprintf(path, sizeof path, "%s/%s", dir, bad[k].name);
        if (veil_write_exr_planes(path, W, H, bad[k].n, names, p, &err) != VEIL_OK) {
            fprintf(stderr, "make_compare_exrs: %s\n", err.msg);
            ok = 0;
        }
        planes[bad[k].plane][bad[k].pixel] = keep;
    }
    return ok ? 0 : 1;
}
