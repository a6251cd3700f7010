/* veil — light from the environment: a constant sky or a lat-long map of
 * radiance around the scene, at infinity (a scene file's light of type
 * "environment", docs/scene-format.md). Pure math, no file format: io/scene.c
 * reads the map (an EXR) into a veil_environment, and these functions give
 *  - the radiance arriving from a direction (the background seen through
 *    the medium, and what the reference path tracer's paths meet);
 *  - the map as a few directional lights (median cut: Debevec, "A Median Cut
 *    Algorithm for Light Probe Sampling", SIGGRAPH 2005 poster / 2006),
 *    which is how the GPU pipeline carries it (or, by default under the
 *    light cache, its bright part): each region of the sphere becomes one
 *    directional light with the region's irradiance, so the light-space
 *    optical depth, the light cache and the march need nothing new;
 *  - the split into that bright part and a smooth rest, and the rest as a
 *    table of texels the light cache's photons start from;
 *  - a distribution of directions proportional to the map's luminance
 *    times solid angle, with its pdf, for the reference's importance
 *    sampling (multiple importance sampling with the phase function).
 *
 * The map. Texel (i, j) of a W x H map (row j = 0 the top) holds the radiance
 * (W m^-2 sr^-1, linear RGB) arriving from every direction of its cell: the
 * map is piecewise constant, no interpolation (so that the median cut's sums,
 * the sampling pdf and the lookups agree exactly). Directions in veil's
 * world, +Y up, `d` the unit direction towards the sky (where light comes
 * from), before rotation:
 *     theta = acos(d.y) in [0, pi]          (row: v = theta / pi, from the top)
 *     phi   = atan2(d.z, d.x) + pi in [0, 2 pi)   (column: u = phi / (2 pi))
 * so the map's middle column looks along +X, a quarter in along -Z and three
 * quarters along +Z: with veil's axes turned into Blender's (Blender
 * (x, y, z) = veil (x, -z, y)) this is Blender's equirectangular
 * environment texture, read with "Closest" interpolation. The texel's cell
 * spans phi in [2 pi i / W, 2 pi (i+1) / W) and theta in [pi j / H, pi (j+1) / H):
 * its solid angle is (2 pi / W) (cos(pi j / H) - cos(pi (j+1) / H)).
 *
 * Rotation: the whole map turned by rotation_deg about +Y (right-handed:
 * +90 brings what was along +X to -Z). Intensity multiplies every texel.
 * A constant sky is a 1 x 1 map.
 *
 * Up "z" (a scene written in a Z-up world, as Blender's add-on writes it):
 * the world's +Z is the zenith, and world direction (x, y, z) looks the map
 * up as (x, z, -y) would above: Blender's own equirectangular convention in
 * Blender's own axes. The rotation is then about +Z (right-handed: +90
 * brings +X to +Y).
 */
#ifndef VEIL_ENVIRONMENT_H
#define VEIL_ENVIRONMENT_H

#include <stddef.h>

#include "../core/result.h"
#include "light.h"

#define VEIL_ENV_CUTS 3 /* median cuts a scene keeps: the given count's, or one for each quality rung's count */
/* The quality rungs' counts (frame/stages.h; docs/accuracy.md measured them): draft, default, high and max */
#define VEIL_ENV_LIGHTS_DRAFT 4
#define VEIL_ENV_LIGHTS_DEFAULT 8
#define VEIL_ENV_LIGHTS_HIGH 16
#define VEIL_ENV_MAX_TEXELS ((size_t)1 << 25) /* an 8K map, 8192 x 4096 */
/* The split, where the light cache carries the remainder (frame/stages.h, docs/accuracy.md): a texel's
 * luminance above VEIL_ENV_CLIP times the map's mean (over the sphere) is its bright part, the median cut's;
 * the rest, at most that luminance, is the cache's photons'. A region of the bright part under
 * VEIL_ENV_POINT_DEG across is one light (a sun), not split further: a 6-degree disc as 4 lights gave no
 * better images than as 1 (docs/accuracy.md), and each light costs a propagation. */
#define VEIL_ENV_CLIP 8.0
#define VEIL_ENV_POINT_DEG 8.0
/* The rest's photon table holds at most this many texels (a larger map is averaged over blocks of texels) */
#define VEIL_ENV_TABLE_TEXELS ((size_t)1 << 19)

typedef struct veil_env_dist veil_env_dist;

/* A median cut: k regions asked for, count lights made (regions without light make none). */
typedef struct veil_env_cut {
    int k, count;
    veil_light lights[VEIL_MAX_LIGHTS];
    int bright_count;                   /* the bright part's cut (veil_env_bright_cut), for the same k */
    veil_light bright[VEIL_MAX_LIGHTS];
} veil_env_cut;

typedef struct veil_environment {
    int present;       /* 0: none (every other field zero) */
    int width, height; /* the map; 1 x 1: a constant sky */
    float* rgb;        /* width * height * 3 radiances, intensity included (owned) */
    float rotation_deg;
    int up_z;          /* 1: "up": "z", the world's +Z is the map's zenith (0: +Y) */
    int lights;        /* "lights": how many directional lights the GPU pipeline carries it as, 1..VEIL_MAX_LIGHTS;
                          0: the quality rung's (frame/stages.h: draft 4, default 8, high and max 16) */
    int room;          /* at most this many: VEIL_MAX_LIGHTS less the scene's other lights */
    int remainder_lights; /* "remainder": "lights": the whole map is the median cut's, even under the light cache
                             (0, "cache": where the cache is the volumetric method, the cut carries the bright
                             part and the cache's photons the rest: veil_env_bright_cut) */
    char* file;        /* the map's file, resolved (owned); NULL: a constant colour */
    size_t light_index; /* where it stood among the scene file's lights (for messages) */
    veil_env_dist* dist; /* the sampling distribution, made on first need (veil_env_dist_make; owned) */
    veil_env_cut cuts[VEIL_ENV_CUTS]; /* made once when the scene is read (veil_env_make_cuts) */
    double clip;       /* the split's luminance: VEIL_ENV_CLIP times the mean (set by veil_env_make_cuts) */
    unsigned long long key; /* the map's content (size, texels, rotation, up) hashed, for the cache's key (ditto) */
    int cut_sets;
} veil_environment;

/* Releases what e owns; leaves it zeroed. */
void veil_env_free(veil_environment* e);

/* The radiance arriving from unit direction d (towards the sky), rgb. */
void veil_env_radiance(const veil_environment* e, const double d[3], double out[3]);

/* Texel (i, j)'s solid angle (sr) in a map h rows high and w wide. */
double veil_env_texel_solid_angle(int w, int h, int j);

/* The integral of the radiance over the sphere, rgb (W/m^2: the irradiance
 * a sphere's point would get from all of it, cos left out). */
void veil_env_integral(const veil_environment* e, double out[3]);

/* The median cut: up to `max` regions of the map, each as a directional
 * light whose irradiance is the region's integral of radiance over solid
 * angle and whose direction is the region's luminance-weighted mean
 * direction (rotation applied). Regions are split, the one carrying the
 * most luminance first, across their longer side (in angle, the width
 * weighted by the sine of the middle row's theta) at the texel boundary
 * that halves the luminance most evenly; regions without light make no
 * light. A constant sky is cut as a 64 x 32 map of itself. Returns the
 * number of lights written (0 when the environment is black); the sum of
 * their irradiances is veil_env_integral's, up to rounding. */
int veil_env_median_cut(const veil_environment* e, int max, veil_light* out);

/* The split at e->clip: each texel's radiance scaled down to luminance clip where it is above it is the
 * rest, what that takes away the bright part (the two sum to the map). The bright part's median cut (as
 * veil_env_median_cut, but each region first shrunk to its texels with light, and one under
 * VEIL_ENV_POINT_DEG across not split): up to max lights, 0 when no texel is above the clip (a constant
 * sky, a smooth one). */
int veil_env_bright_cut(const veil_environment* e, int max, veil_light* out);
/* The mean luminance of the radiance over the sphere. */
double veil_env_mean_luminance(const veil_environment* e);
/* The integral over the sphere of the bright part (bright 1) or the rest (0), rgb. */
void veil_env_part_integral(const veil_environment* e, int bright, double out[3]);
/* The world images of the map frame's axes x, y, z (rotation and up applied): a map-frame direction m is
 * the world's m[0] axes[0] + m[1] axes[1] + m[2] axes[2]. */
void veil_env_frame(const veil_environment* e, float axes[3][3]);

/* The rest as a table for photons (the light cache's: volumetric/cache.h): the map averaged over blocks of
 * block x block texels (1, unless it has over max_texels) into a w x h map; of its n texels with light,
 * entry k is 8 floats: the texel's index (row-major, row 0 the top), the CDF of luminance x solid angle up
 * to and with it, 0, 0, its rgb / luminance, 0. total: the sum of luminance x solid angle (W/m^2);
 * bound: the largest rgb / luminance. No light: n 0, entries NULL. */
typedef struct veil_env_table {
    int w, h, block, n;
    float* entries;
    double total, bound;
} veil_env_table;
veil_result veil_env_rest_table(const veil_environment* e, size_t max_texels, veil_env_table* t, veil_error* err);
void veil_env_table_free(veil_env_table* t);

/* Makes e's cuts for `room` lights at most: the one of e->lights, or with lights 0 one for each of the
 * counts rungs[0 .. n) (each at most room; equal ones once). Reports its progress (core/progress.h,
 * "cutting the environment map") every 2^22 texels visited; a cancel found there stops it with no cuts,
 * and it returns 1 (0 otherwise). */
int veil_env_make_cuts(veil_environment* e, int room, const int* rungs, int n);
/* The cut for `want` lights (e->lights when set, else the rung's `want`), at most e->room: the kept cut of
 * that count, else the first; NULL without an environment. */
const veil_env_cut* veil_env_cut_for(const veil_environment* e, int want);
/* The most lights any of e's cuts makes (0 without an environment). */
int veil_env_cut_max(const veil_environment* e);

/* Importance sampling by luminance x solid angle (a texel chosen with
 * probability proportional to its luminance times its solid angle, then a
 * direction uniform in solid angle within it). A black map samples the
 * sphere uniformly. veil_env_dist_make: VEIL_ERR_OOM only. */
veil_result veil_env_dist_make(veil_environment* e, veil_error* err);
/* Releases e's sampling tables only (e->dist), leaving the rest. */
void veil_env_dist_free(veil_environment* e);
/* A direction d (unit, towards the sky, rotation applied) from uniforms
 * u1, u2, u3 in [0, 1); returns its pdf (per steradian), > 0. */
double veil_env_sample(const veil_environment* e, double u1, double u2, double u3, double d[3]);
/* The pdf (per steradian) with which veil_env_sample gives direction d. */
double veil_env_pdf(const veil_environment* e, const double d[3]);

#endif
