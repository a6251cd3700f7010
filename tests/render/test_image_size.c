/* Whether a frame fits the device (render/march.h, veil_march_check_size;
 * issue 41, item 8: a 16384^2 frame, within the documented limits, failed
 * with GL_OUT_OF_MEMORY after the volume was made):
 *  - a small frame fits;
 *  - under a GPU budget of exactly 1000 x 1000 pixels' worth of the march's
 *    textures (5 rgba32f: 80 MB), 1000 x 1000 fits and 2000 x 1500 is
 *    refused naming the budget, with the largest frame of its shape that
 *    fits: W x H with 5 x 16 x W x H <= 80 MB, within a pixel of the
 *    largest (the bisection's 2^-20 of the side), the shape kept;
 *  - the spread's textures (VEIL_SPREAD_IMAGES) count when it may run;
 *  - 16384^2 (the largest veil renders): on a device that cannot hold it,
 *    refused naming what, never a GL error (llvmpipe holds at most about
 *    1 GiB in one texture: 8192^2 rgba32f); one that can (a GPU of tens of
 *    GB) lets it through, and the GL error state stays clean either way. */
#include <stdio.h>
#include <string.h>

#include "support/check.h"
#include "render/march.h"

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    const veil_gl_info* info = veil_gl_get_info(gl);
    veil_error err = {0};
    CHECK(veil_march_check_size(64, 48, 1, info->hardware, info->memory_budget, &err) == VEIL_OK, "64x48: %s",
          err.msg);
    const unsigned long long budget = 1000ull * 1000ull * 16ull * VEIL_MARCH_IMAGES;
    CHECK(veil_march_check_size(1000, 1000, 0, 1, budget, &err) == VEIL_OK, "1000x1000 in its budget: %s", err.msg);
    veil_result r = veil_march_check_size(2000, 1500, 0, 1, budget, &err);
    int bw = 0, bh = 0;
    const char* at = strstr(err.msg, "renders is ");
    if (at) sscanf(at, "renders is %dx%d", &bw, &bh);
    printf("2000x1500 under 80 MB: %s\n", err.msg);
    /* the largest of the shape: W = 2000 s, H = 1500 s with 2000 x 1500 s^2 <= 1e6: s = 1/sqrt(3) (1154 x 866) */
    CHECK(r == VEIL_ERR_LIMIT && strstr(err.msg, "veil allows itself") && bw >= 1153 && bw <= 1154 &&
              bh >= 865 && bh <= 866 && (double)bw * bh <= 1e6,
          "2000x1500: %s: %s (largest %dx%d)", veil_result_name(r), err.msg, bw, bh);
    /* the spread's textures: 9 rgba32f, over the same budget at 1000 x 1000 */
    r = veil_march_check_size(1000, 1000, 1, 1, budget, &err);
    CHECK(r == VEIL_ERR_LIMIT && strstr(err.msg, "9 rgba32f textures"), "1000x1000 with the spread: %s", err.msg);
    r = veil_march_check_size(16384, 16384, 0, info->hardware, info->memory_budget, &err);
    printf("16384x16384 on %s: %s\n", info->renderer, r == VEIL_OK ? "fits" : err.msg);
    CHECK(r == VEIL_OK || (r == VEIL_ERR_LIMIT && strstr(err.msg, "a 16384x16384 image: ") &&
                           strstr(err.msg, "the largest image of this shape this device renders is")),
          "16384x16384: %s: %s", veil_result_name(r), err.msg);
    CHECK(info->hardware || r == VEIL_ERR_LIMIT, "a software rasteriser let a 16384^2 frame through");
    CHECK(glGetError() == GL_NO_ERROR, "the check left a GL error");
    veil_gl_destroy(gl);
    return check_finish();
}
