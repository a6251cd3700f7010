#define _POSIX_C_SOURCE 200809L
/* Frames of a sequence (frame/frames.h): ranges, shards, file-name
 * patterns, the orbit's cameras and the per-frame seeds. The orbit is
 * checked against what it must keep: the distance to the look-at point
 * (rounding of a float position of magnitude <= 10: 1e-5 relative), the
 * angle between consecutive frames (degrees / count), the elevation.
 * A frame's EXR header: the camera matrices put the look-at point at the
 * image's centre and each pixel's ray through its centre (float
 * arithmetic on coordinates of magnitude <= 10: 1e-5 of the image), and
 * they, the frame and the strings read back as written, bit for bit. */
#include <limits.h>
#include <math.h>
#include <string.h>

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "support/check.h"
#include "frame/frames.h"
#include "io/image.h"
#include "scene/camera.h"

static void test_ranges(void)
{
    veil_frame_range r;
    veil_error err = {0};
    CHECK(veil_frame_range_parse("1001-1100", &r, &err) == VEIL_OK && r.first == 1001 && r.last == 1100 && r.step == 1 &&
              veil_frame_range_count(&r) == 100, "1001-1100");
    CHECK(veil_frame_range_parse("1-10x3", &r, &err) == VEIL_OK && veil_frame_range_count(&r) == 4 &&
              veil_frame_range_at(&r, 3) == 10, "1-10x3: %ld frames", veil_frame_range_count(&r));
    CHECK(veil_frame_range_parse("-5--1", &r, &err) == VEIL_OK && r.first == -5 && r.last == -1, "-5--1");
    CHECK(veil_frame_range_parse("42", &r, &err) == VEIL_OK && r.first == 42 && veil_frame_range_count(&r) == 1, "42");
    const char* bad[] = {"", "a", "10-1", "1-10x0", "1-10x", "1-", "1-10y2", "1.5-3", "1-99999999999", " 1-2"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; ++i)
        CHECK(veil_frame_range_parse(bad[i], &r, &err) != VEIL_OK && strstr(err.msg, "range"), "'%s' accepted", bad[i]);
    int s, n;
    CHECK(veil_shard_parse("3/4", &s, &n, &err) == VEIL_OK && s == 3 && n == 4, "3/4");
    const char* bad_shards[] = {"0/4", "5/4", "1/0", "1", "1/2x", "/2", "a/b"};
    for (size_t i = 0; i < sizeof bad_shards / sizeof *bad_shards; ++i)
        CHECK(veil_shard_parse(bad_shards[i], &s, &n, &err) != VEIL_OK, "shard '%s' accepted", bad_shards[i]);
}

static void test_patterns(void)
{
    char out[64];
    veil_error err = {0};
    struct {
        const char* pattern;
        long frame;
        const char* want;
    } ok[] = {{"f/smoke.####.exr", 42, "f/smoke.0042.exr"}, {"smoke.%04d.exr", 1001, "smoke.1001.exr"},
              {"a%d.exr", 7, "a7.exr"},                   {"##.png", 123, "123.png"},
              {"100%%_#.exr", 5, "100%_5.exr"},           {"s.####.exr", -3, "s.-0003.exr"}};
    for (size_t i = 0; i < sizeof ok / sizeof *ok; ++i) {
        veil_result r = veil_frame_pattern_path(ok[i].pattern, ok[i].frame, out, sizeof out, &err);
        CHECK(r == VEIL_OK && !strcmp(out, ok[i].want), "'%s' frame %ld: '%s' (want '%s')", ok[i].pattern, ok[i].frame,
              r == VEIL_OK ? out : err.msg, ok[i].want);
    }
    CHECK(veil_frame_pattern_kind("plain.exr") == 0, "no number");
    const char* bad[] = {"a.##.##.exr", "a.%04d.#.exr", "a.%5d.exr", "a.%s.exr", "a.%04x.exr", "a.%"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; ++i) {
        CHECK(veil_frame_pattern_kind(bad[i]) == -1, "'%s': kind %d", bad[i], veil_frame_pattern_kind(bad[i]));
        CHECK(veil_frame_pattern_path(bad[i], 1, out, sizeof out, &err) == VEIL_ERR_INVALID, "'%s' accepted", bad[i]);
    }
    char tiny[8];
    CHECK(veil_frame_pattern_path("long.####.exr", 1, tiny, sizeof tiny, &err) == VEIL_ERR_LIMIT, "too long a name");
    /* a run of # longer than any number (issue 22: 32 or more # overflowed a 32-byte buffer, found by
     * fuzz_scene): 40 digits, zero-padded, whole; in a buffer too small for them, refused */
    char pat[64], want[64], big[128];
    snprintf(pat, sizeof pat, "f.%s.exr", "########################################");
    snprintf(want, sizeof want, "f.%s7.exr", "000000000000000000000000000000000000000");
    CHECK(veil_frame_pattern_path(pat, 7, big, sizeof big, &err) == VEIL_OK && !strcmp(big, want),
          "40 #: '%s' (want '%s')", big, want);
    char mid[32];
    CHECK(veil_frame_pattern_path(pat, 7, mid, sizeof mid, &err) == VEIL_ERR_LIMIT, "40 # in 32 bytes accepted");
    /* the most negative frame: its magnitude does not fit a long */
    char lmin[64];
    snprintf(lmin, sizeof lmin, "f.-%lu.exr", 0UL - (unsigned long)LONG_MIN);
    CHECK(veil_frame_pattern_path("f.#.exr", LONG_MIN, big, sizeof big, &err) == VEIL_OK && !strcmp(big, lmin),
          "LONG_MIN: '%s' (want '%s')", big, lmin);
}

static double dist(const float a[3], const float b[3])
{
    double d = 0;
    for (int k = 0; k < 3; ++k) d += ((double)a[k] - b[k]) * ((double)a[k] - b[k]);
    return sqrt(d);
}

static void test_orbit(void)
{
    veil_camera c = {.position = {1, 2, 6}, .look_at = {1, 1, 0}, .up = {0, 1, 0}, .fov_y_deg = 40};
    double r = dist(c.position, c.look_at);
    veil_orbit o = {.degrees = 360};
    veil_camera f0 = veil_orbit_camera(&c, &o, 0, 8);
    CHECK(dist(f0.position, c.position) < 1e-5 * r, "frame 0 of a full turn is the scene's camera");
    for (long i = 0; i < 8; ++i) {
        veil_camera a = veil_orbit_camera(&c, &o, i, 8), b = veil_orbit_camera(&c, &o, i + 1, 8);
        CHECK(fabs(dist(a.position, a.look_at) - r) < 1e-5 * r, "frame %ld: distance %g, not %g", i,
              dist(a.position, a.look_at), r);
        CHECK(fabs(a.position[1] - c.position[1]) < 1e-5 * r, "frame %ld: left the orbit's plane", i);
        /* consecutive frames 45 degrees apart about the up axis: chord 2 r_h sin(22.5 deg), r_h the radius about the axis */
        double rh = sqrt(pow(c.position[0] - c.look_at[0], 2) + pow(c.position[2] - c.look_at[2], 2));
        CHECK(fabs(dist(a.position, b.position) - 2 * rh * sin(VEIL_PI / 8)) < 1e-5 * r, "frames %ld, %ld: chord %g", i,
              i + 1, dist(a.position, b.position));
    }
    veil_camera f8 = veil_orbit_camera(&c, &o, 8, 8);
    CHECK(dist(f8.position, c.position) < 1e-5 * r, "a full turn comes back");
    veil_orbit half = {.start_deg = 90, .degrees = 180};
    veil_camera h0 = veil_orbit_camera(&c, &half, 0, 2);
    CHECK(fabs(h0.position[0] - (c.look_at[0] + 6)) < 1e-5 * r && fabs(h0.position[2]) < 1e-5 * r,
          "start 90 degrees: (%g, %g, %g)", h0.position[0], h0.position[1], h0.position[2]);
    veil_orbit up = {.degrees = 360, .elevation_deg = 30};
    veil_camera e = veil_orbit_camera(&c, &up, 0, 4);
    double elev0 = asin((c.position[1] - c.look_at[1]) / r), elev = asin((e.position[1] - e.look_at[1]) / r);
    CHECK(fabs(dist(e.position, e.look_at) - r) < 1e-5 * r && fabs(elev - elev0 - VEIL_PI / 6) < 1e-5,
          "elevation 30: %g degrees more", (elev - elev0) * 180 / VEIL_PI);
    veil_orbit axis = {.axis = {0, 0, 2}, .degrees = 360};
    veil_camera z = veil_orbit_camera(&c, &axis, 1, 4); /* a quarter turn about z: the camera's up becomes z */
    CHECK(z.up[2] == 1.0f && fabs(z.position[2] - c.position[2]) < 1e-5 * r && fabs(dist(z.position, z.look_at) - r) < 1e-5 * r,
          "about z: (%g, %g, %g)", z.position[0], z.position[1], z.position[2]);
}

static void test_seeds(void)
{
    CHECK(veil_frame_seed(0, 1) == veil_frame_seed(0, 1), "a frame's seed is a function of the frame");
    int same = 0;
    for (long f = 0; f < 1000; ++f) same += veil_frame_seed(7, f) == veil_frame_seed(7, f + 1);
    CHECK(same == 0, "%d neighbouring frames share a seed", same);
    CHECK(veil_frame_seed(1, 5) != veil_frame_seed(2, 5), "the base seed matters");
}

/* The lens: the sensor fit and the shift (issue 25) against Blender's
 * definition of the view plane, written in pixels as Blender writes it
 * (BKE_camera_params_compute_viewplane): viewfac = W for a horizontal fit
 * (AUTO: the larger side), H for a vertical one; at unit distance a pixel
 * is 2 tan(fov / 2) / viewfac wide, and the plane spans
 * [-W/2 + shift_x viewfac, W/2 + shift_x viewfac] pixels across (likewise
 * in y). Pixel centres' rays must meet it there, and the EXR header's
 * worldToNDC must map them to their pixel centres. */
static void test_lens(void)
{
    const struct { int fit; int w, h; float shift[2]; } cases[] = {
        {VEIL_FIT_VERTICAL, 64, 48, {0, 0}},     {VEIL_FIT_HORIZONTAL, 64, 48, {0, 0}},
        {VEIL_FIT_AUTO, 64, 48, {0.1f, -0.2f}},  {VEIL_FIT_AUTO, 40, 60, {-0.3f, 0.05f}},
        {VEIL_FIT_HORIZONTAL, 40, 60, {0.25f, 0.25f}}, {VEIL_FIT_VERTICAL, 64, 48, {0.5f, 0}},
    };
    for (size_t n = 0; n < sizeof cases / sizeof cases[0]; ++n) {
        veil_camera c = {.position = {1, 2, 6}, .look_at = {1, 1, 0}, .up = {0, 1, 0}, .fov_y_deg = 50,
                         .sensor_fit = cases[n].fit, .shift = {cases[n].shift[0], cases[n].shift[1]}};
        const int w = cases[n].w, h = cases[n].h;
        veil_camera_basis b;
        veil_error err = {0};
        CHECK(veil_camera_make_basis(&c, w, h, &b, &err) == VEIL_OK, "%s", err.msg);
        int hor = c.sensor_fit == VEIL_FIT_HORIZONTAL || (c.sensor_fit == VEIL_FIT_AUTO && w >= h);
        double viewfac = hor ? w : h, pix = 2.0 * tan(50.0 * VEIL_PI / 360.0) / viewfac;
        /* the camera's frame: unit right, up, forward */
        double R[3], U[3], F[3], nr = 0, nu = 0, nf = 0;
        for (int a = 0; a < 3; ++a) R[a] = b.right[a], U[a] = b.up[a], F[a] = b.fwd[a];
        for (int a = 0; a < 3; ++a) nr += R[a] * R[a], nu += U[a] * U[a], nf += F[a] * F[a];
        for (int a = 0; a < 3; ++a) R[a] /= sqrt(nr), U[a] /= sqrt(nu), F[a] /= sqrt(nf);
        veil_exr_meta m = {0};
        veil_camera_exr_matrices(&b, m.world_to_camera, m.world_to_ndc);
        const int px[3][2] = {{0, 0}, {w - 1, h - 1}, {w / 3, h / 2}};
        for (int k = 0; k < 3; ++k) {
            float dir[3];
            veil_camera_ray(&b, w, h, px[k][0], px[k][1], dir);
            double z = dir[0] * F[0] + dir[1] * F[1] + dir[2] * F[2];
            double x = (dir[0] * R[0] + dir[1] * R[1] + dir[2] * R[2]) / z, y = (dir[0] * U[0] + dir[1] * U[1] + dir[2] * U[2]) / z;
            /* Blender's plane, pixel centres (y up from the bottom: row py is h - 1 - py from it) */
            double want_x = (-0.5 * w + c.shift[0] * viewfac + px[k][0] + 0.5) * pix;
            double want_y = (-0.5 * h + c.shift[1] * viewfac + (h - 1 - px[k][1]) + 0.5) * pix;
            /* float basis: a few ulps of values below ~2 */
            CHECK(fabs(x - want_x) < 1e-5 && fabs(y - want_y) < 1e-5, "case %zu pixel (%d, %d): the ray meets the "
                  "plane at (%g, %g), Blender's at (%g, %g)", n, px[k][0], px[k][1], x, y, want_x, want_y);
            double p4[4] = {b.pos[0] + 3.0 * dir[0], b.pos[1] + 3.0 * dir[1], b.pos[2] + 3.0 * dir[2], 1.0}, q[4] = {0};
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) q[j] += p4[i] * m.world_to_ndc[4 * i + j];
            double nx = (px[k][0] + 0.5) / w, ny = (px[k][1] + 0.5) / h;
            CHECK(fabs(q[0] / q[3] - nx) < 1e-5 && fabs(q[1] / q[3] - ny) < 1e-5,
                  "case %zu pixel (%d, %d) meets NDC (%g, %g), want (%g, %g)", n, px[k][0], px[k][1], q[0] / q[3],
                  q[1] / q[3], nx, ny);
        }
    }
}

static void test_header(void)
{
    veil_camera c = {.position = {1, 2, 6}, .look_at = {1, 1, 0}, .up = {0, 1, 0}, .fov_y_deg = 40};
    const int w = 64, h = 48;
    veil_camera_basis b;
    veil_error err = {0};
    CHECK(veil_camera_make_basis(&c, w, h, &b, &err) == VEIL_OK, "%s", err.msg);
    veil_exr_meta m = {.has_frame = 1, .frame = 1042, .has_camera = 1, .n_strings = 1,
                       .strings = {{"veil:settings", "quality default"}}};
    veil_camera_exr_matrices(&b, m.world_to_camera, m.world_to_ndc);
    /* row vectors: p' = (p, 1) M */
    double cam[4] = {0}, ndc[4] = {0};
    const float* p = c.look_at;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            double pi = i < 3 ? p[i] : 1.0;
            cam[j] += pi * m.world_to_camera[4 * i + j];
            ndc[j] += pi * m.world_to_ndc[4 * i + j];
        }
    double d = sqrt(37.0);
    CHECK(fabs(cam[0]) < 1e-5 && fabs(cam[1]) < 1e-5 && fabs(cam[2] - d) < 1e-5,
          "the look-at point in camera space: (%g, %g, %g), want (0, 0, %g)", cam[0], cam[1], cam[2], d);
    CHECK(fabs(ndc[0] / ndc[3] - 0.5) < 1e-5 && fabs(ndc[1] / ndc[3] - 0.5) < 1e-5, "the look-at point at NDC (%g, %g)",
          ndc[0] / ndc[3], ndc[1] / ndc[3]);
    const int px[3][2] = {{0, 0}, {63, 47}, {10, 30}};
    for (int k = 0; k < 3; ++k) {
        float dir[3];
        veil_camera_ray(&b, w, h, px[k][0], px[k][1], dir);
        double x[4] = {b.pos[0] + 3.0 * dir[0], b.pos[1] + 3.0 * dir[1], b.pos[2] + 3.0 * dir[2], 1.0}, q[4] = {0};
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) q[j] += x[i] * m.world_to_ndc[4 * i + j];
        double want_x = (px[k][0] + 0.5) / w, want_y = (px[k][1] + 0.5) / h;
        CHECK(fabs(q[0] / q[3] - want_x) < 1e-5 && fabs(q[1] / q[3] - want_y) < 1e-5,
              "pixel (%d, %d)'s ray meets NDC (%g, %g), want (%g, %g)", px[k][0], px[k][1], q[0] / q[3], q[1] / q[3],
              want_x, want_y);
    }
    char path[] = "/tmp/veil_test_header_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0, "mkstemp");
    if (fd < 0) return;
    close(fd);
    float plane[12] = {0};
    const float* planes[1] = {plane};
    const char* names[1] = {"R"};
    CHECK(veil_write_exr_planes_meta(path, 4, 3, 1, names, planes, &m, &err) == VEIL_OK, "%s", err.msg);
    int has_frame = 0, frame = 0, has_camera = 0;
    float wc[16], wn[16];
    char value[64];
    CHECK(veil_read_exr_meta(path, &has_frame, &frame, &has_camera, wc, wn, "veil:settings", value, sizeof value,
                             &err) == VEIL_OK, "%s", err.msg);
    CHECK(has_frame && frame == 1042, "frame %d (%d)", frame, has_frame);
    CHECK(has_camera && !memcmp(wc, m.world_to_camera, sizeof wc) && !memcmp(wn, m.world_to_ndc, sizeof wn),
          "the matrices did not come back as written");
    CHECK(!strcmp(value, "quality default"), "the settings string: '%s'", value);
    CHECK(veil_write_exr_planes(path, 4, 3, 1, names, planes, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_read_exr_meta(path, &has_frame, &frame, &has_camera, wc, wn, "veil:settings", value, sizeof value,
                             &err) == VEIL_OK && !has_frame && !has_camera && !value[0],
          "a file written without a header's attributes has them");
    unlink(path);
}

int main(void)
{
    test_header();
    test_lens();
    test_ranges();
    test_patterns();
    test_orbit();
    test_seeds();
    return check_finish();
}
