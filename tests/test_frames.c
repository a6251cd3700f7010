/* Frames of a sequence (frame/frames.h): ranges, shards, file-name
 * patterns, the orbit's cameras and the per-frame seeds. The orbit is
 * checked against what it must keep: the distance to the look-at point
 * (rounding of a float position of magnitude <= 10: 1e-5 relative), the
 * angle between consecutive frames (degrees / count), the elevation. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "frame/frames.h"

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

int main(void)
{
    test_ranges();
    test_patterns();
    test_orbit();
    test_seeds();
    return check_finish();
}
