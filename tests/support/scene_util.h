/* veil tests — a scene from a JSON string or from a shared test scene of
 * tests/data/scenes/, and the ray of a 1x1 image. */
#ifndef VEIL_TEST_SCENE_UTIL_H
#define VEIL_TEST_SCENE_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/scene.h"
#include "scene/camera.h"

/* Parses json or exits 1 (the test's own scene must be valid). */
static inline veil_scene test_parse_scene(const char* json)
{
    veil_scene s;
    veil_error e = {0};
    if (veil_scene_parse("test.json", json, strlen(json), &s, &e) != VEIL_OK) {
        fprintf(stderr, "scene: %s\n", e.msg);
        exit(1);
    }
    return s;
}

/* A scene several tests share, tests/data/scenes/NAME (VEIL_TEST_SCENES is
 * that folder, defined by tests/support/CMakeLists.txt), or exits 1. */
static inline veil_scene test_load_scene(const char* name)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", VEIL_TEST_SCENES, name);
    veil_scene s;
    veil_error e = {0};
    if (veil_scene_load(path, &s, &e) != VEIL_OK) {
        fprintf(stderr, "scene: %s\n", e.msg);
        exit(1);
    }
    return s;
}

/* s with multiple scattering off: the scene as the single-scattering march
 * sees it (the closed forms of single scattering and transmittance). */
static inline veil_scene test_single_scattering(veil_scene s)
{
    s.multiple.screen_space = 0;
    s.multiple.volumetric = 0;
    return s;
}

static inline veil_scene test_parse_scene_single(const char* json)
{
    return test_single_scattering(test_parse_scene(json));
}

/* The ray of a 1x1 image as the renderers form it (float camera, then
 * promoted), so that closed forms see exactly its inputs. */
static inline void test_camera_ray(const veil_scene* s, double o[3], double d[3])
{
    veil_camera_basis b;
    veil_error err = {0};
    veil_camera_make_basis(&s->camera, 1, 1, &b, &err);
    float df[3];
    veil_camera_ray(&b, 1, 1, 0, 0, df);
    double n = 0.0;
    for (int k = 0; k < 3; ++k) {
        o[k] = b.pos[k];
        d[k] = df[k];
        n += d[k] * d[k];
    }
    for (int k = 0; k < 3; ++k) d[k] /= sqrt(n);
}

#endif
