/* Stress: seeded random extreme scenes through the whole pipeline.
 *
 * Each scene is written as JSON and read by veil_scene_parse, with random
 * combinations of: the voxel edge anywhere in 1e-4 ... 1e4 m (the whole
 * scene scaled), peak densities 1e-6 ... 1e6 (log-uniform), HG g in
 * [-0.99, 0.99], sigma_a / sigma_s from 0 to very opaque per channel,
 * lights on a particle's or a voxel's centre, near, and 1e6 m away (point,
 * spot, directional), the camera inside the medium, zero-size sources
 * (zero amplitudes, min == max bounds, flat boxes), exponential fog with
 * extreme falloff, and fog 2e7 m across. One renderer renders them all
 * (16x12 pixels, max_resolution 8 ... 24).
 *
 * Asserted for every scene the library accepts:
 *  - the image: every value finite, R, G, B >= 0, alpha in [0, 1];
 *  - transmittance does not increase along rays: the scene is rendered
 *    again with max_distance at three increasing distances spanning the
 *    medium. Those renders march exactly the steps of the full render up to
 *    the limit (frame/renderer.h), T only ever multiplies by
 *    exp(-x) <= 1 with x >= 0, and rounding is monotone (a smaller factor
 *    or a smaller channel never rounds to a larger product or sum), so per
 *    pixel alpha must be non-decreasing with max_distance EXACTLY: no
 *    tolerance;
 *  - the GPU optical depth (veil_renderer_propagate, the scene's method and
 *    the renderer's tolerance) of every light: finite and >= 0;
 *  - the CPU ground truth veil_ref_optical_depth at random points: finite,
 *    >= 0, and non-decreasing as the point moves along the light's path away
 *    from the light (the longer path contains the shorter one); tolerance in
 *    ref_tolerance() below;
 *  - the CPU path tracer (reference/pathtracer.h: 8x6 pixels, 2 samples,
 *    every scattering order, 2 threads) on the same scene where its cost is
 *    bounded (PT_MAX_TAU_MAJ below): image and standard errors finite, RGB
 *    and errors >= 0, alpha in [0, 1]; its cut walks and dropped samples are
 *    counted and printed.
 * A scene the library rejects with an error is counted (and its message
 * shown); more than 5 % rejected means the generator makes invalid scenes. The light cache: 4096 photons.
 *   test_stress [SCENES [SEED [FIRST]]]   (default 500 scenes, seed 3, from scene 0)
 * Scene i draws from its own stream (SEED, i): `test_stress 1 SEED i` redoes it alone. */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "io/scene.h"
#include "propagate/opv.h"
#include "reference/optical_depth.h"
#include "reference/pathtracer.h"
#include "gpu/gl_util.h"
#include "frame/renderer.h"
#include "support/seeded_random.h"
#include "volume/scene_volume.h"

enum { W = 16, H = 12, MAX_ANCHORS = 64, REF_POINTS = 3, REF_STEPS = 5, MAX_DUMPS = 3 };
enum { PT_W = 8, PT_H = 6 }; /* the CPU path tracer's image */
/* The path tracer's delta and ratio tracking take a tentative collision per
 * unit of majorant optical depth that they cross (null collisions too: in
 * the volume where the density is below its block maximum, and in fog for
 * channels whose sigma_t is below the largest, spectral tracking), so its
 * cost grows with tau_maj = max sigma_t * sum over the volume and the fogs
 * of (peak density * box diagonal): 1e7 and more in these scenes, i.e.
 * minutes to hours, walks cut at VEIL_PT_MAX_EVENTS. A path has ~20-40
 * vertices (Russian roulette from the 16th, survival 0.95), each crossing
 * the medium about 1 + lights times: at tau_maj <= 1e4 a scene costs at most
 * ~48 pixels x 2 samples x 40 x 5 x 1e4 = 2e8 collisions (seconds; most
 * paths leave or are absorbed far sooner: 6e6 in all 500 scenes). Scenes
 * above it skip the path tracer (counted). */
#define PT_MAX_TAU_MAJ 1e4

static double diagonal(const float lo[3], const float hi[3])
{
    return sqrt(pow((double)hi[0] - lo[0], 2) + pow((double)hi[1] - lo[1], 2) + pow((double)hi[2] - lo[2], 2));
}

/* tau_maj of PT_MAX_TAU_MAJ, in logs (fog densities can pass 1e308). */
static double log_majorant_depth(const veil_scene* s, const veil_scene_volume* v, const float* rho)
{
    double st = 0.0, sum = 0.0, terms[1 + VEIL_MAX_FOGS], mx = -INFINITY;
    for (int c = 0; c < 3; ++c) st = fmax(st, (double)s->medium.sigma_a[c] + s->medium.sigma_s[c]);
    int n = 0;
    if (rho) {
        float rmax = 0.0f, lo[3], hi[3];
        for (size_t i = 0; i < veil_grid_voxels(&v->grid); ++i) rmax = fmaxf(rmax, rho[i]);
        veil_grid_medium_box(&v->grid, lo, hi);
        terms[n++] = log((double)rmax * (diagonal(lo, hi) + v->grid.voxel));
    }
    for (size_t i = 0; i < s->medium.source_count && n < 1 + VEIL_MAX_FOGS; ++i) {
        const veil_exp_fog* f = &s->medium.sources[i].fog;
        if (s->medium.sources[i].type != VEIL_SOURCE_EXPONENTIAL || !(f->density > 0.0f)) continue;
        double kmin = INFINITY; /* the least falloff <x - origin, n> over the box: at a corner */
        for (int c = 0; c < 8; ++c) {
            double k = 0.0;
            for (int a = 0; a < 3; ++a) k += ((double)f->bounds[(c >> a) & 1][a] - f->origin[a]) * f->direction[a];
            kmin = fmin(kmin, (double)f->falloff * k);
        }
        terms[n++] = log(f->density) - kmin + log(diagonal(f->bounds[0], f->bounds[1]));
    }
    for (int i = 0; i < n; ++i) mx = fmax(mx, terms[i]);
    for (int i = 0; i < n && isfinite(mx); ++i) sum += exp(terms[i] - mx);
    return !(st > 0.0) ? -INFINITY : !isfinite(mx) ? mx : log(st) + mx + log(sum);
}

/* ---- a growing string ------------------------------------------------------ */

typedef struct sbuf {
    char* p;
    size_t len, cap;
} sbuf;

static void sb_add(sbuf* b, const char* fmt, ...)
{
    va_list ap, ap2;
    va_start(ap, fmt);
    va_copy(ap2, ap);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0) n = 0;
    if (b->len + (size_t)n + 1 > b->cap) {
        b->cap = 2 * (b->len + (size_t)n + 1) + 256;
        if (!(b->p = realloc(b->p, b->cap))) exit(1); /* out of memory */
    }
    vsnprintf(b->p + b->len, b->cap - b->len, fmt, ap2);
    va_end(ap2);
    b->len += (size_t)n;
}

#define VF "[%.9g, %.9g, %.9g]" /* a vector: VF in the format, V3(v) in the arguments */
#define V3(v) (v)[0], (v)[1], (v)[2]

/* ---- the scene generator ---------------------------------------------------- */

/* What the generator chose, for the checks and the summary. */
typedef struct gen_scene {
    double s;                    /* length scale (m): the medium lies within about o +- s */
    double o[3];                 /* its centre */
    double anchors[MAX_ANCHORS][3]; /* particle centres and o: where lights and the camera may sit */
    int n_anchors;
    double cam[3];
    int voxel_light[VEIL_MAX_LIGHTS]; /* 1: move onto a voxel centre once the grid is known */
    /* features, counted in the summary */
    int cam_inside, light_at_centre, light_far, zero_size, steep_fog, huge_fog, sigma_zero;
    double huge_n[3]; /* the huge fog's direction */
} gen_scene;

enum { F_CAM_INSIDE, F_LIGHT_CENTRE, F_LIGHT_FAR, F_ZERO_SIZE, F_STEEP_FOG, F_HUGE_FOG, F_SIGMA_ZERO, F_COUNT };
static const char* const feature_names[F_COUNT] = {"camera inside", "light on a particle/voxel centre",
                                                   "light 1e6 m away", "zero-size source",
                                                   "fog falloff*size > 100", "fog 2e7 m across at its density cap",
                                                   "a zero sigma_t channel"};

static int chance(double p) { return rnd() < p; }

static void point_in(const gen_scene* g, double spread, double out[3])
{
    for (int a = 0; a < 3; ++a) out[a] = g->o[a] + g->s * rnd_in(-spread, spread);
}

static void add_anchor(gen_scene* g, const double p[3])
{
    if (g->n_anchors < MAX_ANCHORS) memcpy(g->anchors[g->n_anchors++], p, sizeof(double[3]));
}

static const double* any_anchor(const gen_scene* g) { return g->anchors[(int)(rnd() * g->n_anchors)]; }

static void colour(double c[3], double lo, double hi, double scale, double p_zero)
{
    for (int k = 0; k < 3; ++k) c[k] = chance(p_zero) ? 0.0 : rnd_log(lo, hi) * scale;
}

/* A box in o +- s: usually a random sub-box; zero-size (min == max) or flat
 * along one axis now and then. */
static void gen_box(sbuf* b, gen_scene* g, double spread)
{
    double lo[3], hi[3];
    point_in(g, spread, lo);
    memcpy(hi, lo, sizeof hi);
    int kind = (int)(rnd() * 10);
    for (int a = 0; a < 3; ++a) {
        if (kind == 0 || (kind == 1 && a == 1)) continue; /* a point; flat */
        lo[a] = g->o[a] - g->s * rnd_in(0.1, spread);
        hi[a] = g->o[a] + g->s * rnd_in(0.1, spread);
    }
    g->zero_size |= kind <= 1;
    sb_add(b, "[" VF ", " VF "]", V3(lo), V3(hi));
}

static void gen_rbf(sbuf* b, gen_scene* g, double rho)
{
    int n = 1 + (int)(rnd() * 5), mode = (int)(rnd() * 6);
    double one[3];
    point_in(g, 0.7, one);
    sb_add(b, "{\"type\": \"rbf\", \"particles\": [");
    for (int i = 0; i < n; ++i) {
        double c[3];
        if (mode == 1) memcpy(c, one, sizeof c); /* all at one point */
        else point_in(g, 0.7, c);
        add_anchor(g, c);
        double amp = mode == 2 ? 0.0 : rho * rnd_in(0.05, 1.0); /* mode 2: zero amplitude */
        /* mode 3: particles much smaller than a voxel */
        double radius = g->s * (mode == 3 ? rnd_log(1e-4, 1e-2) : rnd_log(0.05, 0.8));
        sb_add(b, "%s{\"center\": " VF ", \"amplitude\": %.9g, \"sharpness\": %.9g}", i ? ", " : "", V3(c), amp,
               1.0 / radius);
    }
    g->zero_size |= mode == 1 || mode == 2;
    sb_add(b, "]}");
}

static void gen_random(sbuf* b, gen_scene* g, double rho)
{
    double r0 = g->s * rnd_log(0.03, 0.5), r1 = r0 * rnd_in(1.0, 3.0);
    double c0 = chance(0.3) ? 0.0 : rho * rnd_in(0.0, 0.5), c1 = chance(0.05) ? c0 : c0 + rho * rnd_in(0.0, 1.0);
    sb_add(b, "{\"type\": \"rbf_random\", \"count\": %d, \"seed\": %llu, \"bounds\": ", (int)(rnd() * 60),
           (unsigned long long)(rnd() * 1e15));
    gen_box(b, g, 0.8);
    sb_add(b, ", \"radius\": [%.9g, %.9g], \"amplitude\": [%.9g, %.9g]}", r0, r1, c0, c1);
}

static void gen_fog(sbuf* b, gen_scene* g, double rho)
{
    double n[3], origin[3];
    rnd_unit(n);
    if (chance(0.3)) n[0] = 0, n[1] = 1, n[2] = 0;
    if (chance(0.1)) {
        /* a fog 2e7 m across whose origin plane lies 70 / falloff above the
         * scene: the density there is at the marcher's cap rho e^60, and paths
         * of ~1e7 m across n through it overflow float for rho >~ 3e5 */
        const double bf = rnd_log(1e-4, 1e-1), lo[3] = {g->o[0] - 1e7, g->o[1] - 1e7, g->o[2] - 1e7};
        const double hi[3] = {g->o[0] + 1e7, g->o[1] + 1e7, g->o[2] + 1e7};
        for (int a = 0; a < 3; ++a) origin[a] = g->o[a] + 70.0 / bf * n[a];
        sb_add(b, "{\"type\": \"exponential\", \"density\": %.9g, \"falloff\": %.9g, \"direction\": " VF
                  ", \"origin\": " VF ", \"bounds\": [" VF ", " VF "]}",
               rnd_log(1e5, 1e6), bf, V3(n), V3(origin), V3(lo), V3(hi));
        g->huge_fog = 1;
        memcpy(g->huge_n, n, sizeof n);
        return;
    }
    point_in(g, 1.0, origin);
    /* falloff * s from 0 (homogeneous) to 1e4 (the density changes by e^1e4
     * across the scene: capped at exp(VEIL_FOG_MAX_EXPONENT) in the marcher) */
    double bs = chance(0.2) ? 0.0 : rnd_log(1e-3, 1e4);
    g->steep_fog |= bs > 100.0;
    sb_add(b, "{\"type\": \"exponential\", \"density\": %.9g, \"falloff\": %.9g, \"direction\": " VF
              ", \"origin\": " VF, rho * rnd(), bs / g->s, V3(n), V3(origin));
    if (!chance(0.2)) { /* else the default: a 1000 m cube around the origin */
        sb_add(b, ", \"bounds\": ");
        gen_box(b, g, 1.5);
    }
    sb_add(b, "}");
}

static void gen_light(sbuf* b, gen_scene* g, int l)
{
    int type = (int)(rnd() * 3);
    double d[3], c[3], p[3], ref = g->s;
    rnd_unit(d);
    if (type == 1) { /* directional: random, axis-aligned or nearly so */
        if (chance(0.2)) d[0] = 0, d[1] = -1, d[2] = 0;
        else if (chance(0.1)) d[0] = 1e-7, d[1] = -1, d[2] = 0;
        /* across a huge fog's n: the path to the light stays at its density
         * cap for ~1e7 m (along n the closed form integrates the decay, ~cap / falloff) */
        if (g->huge_fog && chance(0.5)) {
            const double* n = g->huge_n;
            double x[3] = {n[1] * d[2] - n[2] * d[1], n[2] * d[0] - n[0] * d[2], n[0] * d[1] - n[1] * d[0]};
            if (dot3(x, x) > 1e-6) memcpy(d, x, sizeof d);
        }
        colour(c, 1e-2, 1e2, 1.0, 0.1);
        sb_add(b, "{\"type\": \"directional\", \"direction\": " VF ", \"irradiance\": " VF "}", V3(d), V3(c));
        return;
    }
    int where = (int)(rnd() * 4);
    if (where == 0) { /* on a particle's centre (or o), or a hair beside it */
        memcpy(p, any_anchor(g), sizeof p);
        if (chance(0.5))
            for (int a = 0; a < 3; ++a) p[a] += g->s * 1e-7 * rnd_in(-1, 1);
        g->light_at_centre = 1;
    } else if (where == 1) { /* 1e6 m away */
        double u[3];
        rnd_unit(u);
        for (int a = 0; a < 3; ++a) p[a] = g->o[a] + 1e6 * u[a];
        ref = 1e6;
        g->light_far = 1;
    } else if (where == 2) { /* onto a voxel centre, after parsing */
        memcpy(p, g->o, sizeof p);
        g->voxel_light[l] = g->light_at_centre = 1;
    } else {
        point_in(g, 1.5, p);
    }
    colour(c, 1e-2, 1e2, ref * ref, 0.1); /* W/sr: radiance-sized at distance ref */
    sb_add(b, "{\"type\": \"%s\", \"position\": " VF ", \"intensity\": " VF, type == 0 ? "point" : "spot", V3(p),
           V3(c));
    if (type == 2) {
        if (chance(0.6)) /* toward the medium */
            for (int a = 0; a < 3; ++a) d[a] = g->o[a] - p[a] + 0.2 * g->s * d[a];
        if (!(fabs(d[0]) + fabs(d[1]) + fabs(d[2]) > 0)) d[1] = -1;
        double outer = chance(0.1) ? 180.0 : (chance(0.1) ? 0.01 : rnd_in(1.0, 179.0));
        double inner = chance(0.3) ? 0.0 : outer * rnd_in(0.0, 0.999);
        sb_add(b, ", \"direction\": " VF ", \"inner_angle_deg\": %.9g, \"outer_angle_deg\": %.9g", V3(d), inner,
               outer);
    }
    sb_add(b, "}");
}

static void gen_camera(sbuf* b, gen_scene* g)
{
    double look[3], u[3];
    int where = (int)(rnd() * 10);
    rnd_unit(u);
    if (where < 3) { /* inside the medium: at a particle's centre or near o */
        if (chance(0.5)) memcpy(g->cam, any_anchor(g), sizeof g->cam);
        else point_in(g, 0.4, g->cam);
        for (int a = 0; a < 3; ++a) look[a] = g->cam[a] + g->s * u[a];
        g->cam_inside = 1;
    } else { /* outside, or (1 in 7) far away with a narrow view */
        double dist = where == 9 ? 1e3 : rnd_in(2.5, 6.0);
        for (int a = 0; a < 3; ++a) g->cam[a] = g->o[a] + g->s * dist * u[a];
        point_in(g, 0.2, look);
    }
    double f[3] = {look[0] - g->cam[0], look[1] - g->cam[1], look[2] - g->cam[2]}, up[3] = {0, 1, 0};
    if (fabs(f[1]) > 0.9 * sqrt(dot3(f, f))) up[1] = 0, up[0] = 1;
    sb_add(b, "\"camera\": {\"position\": " VF ", \"look_at\": " VF ", \"up\": " VF
              ", \"fov_y_deg\": %.9g, \"width\": %d, \"height\": %d}",
           V3(g->cam), V3(look), V3(up), where == 9 ? 0.5 : rnd_in(10, 90), W, H);
}

static void gen_scene_json(sbuf* b, gen_scene* g)
{
    memset(g, 0, sizeof *g);
    b->len = 0;
    const int res = 8 + (int)(rnd() * 17);
    g->s = rnd_log(1e-4, 1e4) * 0.5 * (res - 1); /* voxel edge ~ 2 s / (res - 1) */
    for (int a = 0; a < 3; ++a) g->o[a] = g->s * rnd_in(-5, 5);
    add_anchor(g, g->o);
    const double rho = rnd_log(1e-6, 1e6);
    double sa[3], ss[3], bg[3];
    int kind = (int)(rnd() * 10);
    for (int k = 0; k < 3; ++k) {
        /* per unit density, a tau of 1e-3 ... 1e3 across the scene; or (kind 9)
         * not scaled with it: tiny scenes clear, huge ones opaque */
        double unit = kind == 9 ? 1.0 : 1.0 / (2.0 * g->s);
        sa[k] = kind <= 1 || chance(0.3) ? 0.0 : rnd_log(1e-3, 1e3) * unit;
        ss[k] = kind == 0 || chance(0.15) ? 0.0 : rnd_log(1e-3, 1e3) * unit;
        g->sigma_zero |= sa[k] + ss[k] == 0.0;
    }
    sb_add(b, "{\"medium\": {\"sigma_a\": " VF ", \"sigma_s\": " VF, V3(sa), V3(ss));
    if (chance(0.3)) sb_add(b, ", \"phase\": {\"type\": \"isotropic\"}");
    else sb_add(b, ", \"phase\": {\"type\": \"hg\", \"g\": %.9g}", chance(0.2) ? (chance(0.5) ? 0.99 : -0.99) : rnd_in(-0.99, 0.99));
    sb_add(b, ", \"max_resolution\": %d, \"sources\": [", res);
    int n_src = chance(0.02) ? 0 : 1 + (int)(rnd() * 3), fogs = 0;
    for (int i = 0; i < n_src; ++i) {
        if (i) sb_add(b, ", ");
        double x = rnd(), r = rho * rnd_log(1e-2, 1.0); /* the sources' densities differ */
        if (x < 0.4) gen_rbf(b, g, r);
        else if (x < 0.7 || fogs == VEIL_MAX_FOGS) gen_random(b, g, r);
        else gen_fog(b, g, r), ++fogs;
    }
    sb_add(b, "]}, \"lights\": [");
    const int n_lights = chance(0.05) ? 0 : 1 + (int)(rnd() * 4);
    for (int l = 0; l < n_lights; ++l) {
        if (l) sb_add(b, ", ");
        gen_light(b, g, l);
    }
    sb_add(b, "], ");
    gen_camera(b, g);
    colour(bg, 1e-2, 1e1, 1.0, 0.3);
    /* the light cache on a small budget: its guards and bounds are stressed, not its noise */
    sb_add(b, ", \"background\": {\"color\": " VF "}, \"multiple_scattering\": {\"cache_photons\": 4096, "
              "\"cache_cells\": 8}}", V3(bg));
}

/* ---- checks ----------------------------------------------------------------- */

typedef struct totals {
    int scenes, rejected, failed_scenes;
    long pixels_bad, monotone_bad, opv_bad, ref_bad, ref_checked;
    double max_alpha, max_rgb, max_D_gpu, max_D_ref, worst_ref_drop;
    int features[F_COUNT];
    int opaque_scenes, clear_scenes;
    double ms_gpu, ms_cpu, slowest_ms; /* wall time (GPU: renders and D; CPU: D and path tracer); the slowest */
    int slowest;
    long pt_bad;
    int pt_rejected, pt_run, pt_skipped;
    uint64_t pt_cut_walks, pt_dropped, pt_paths, pt_collisions;
    double pt_max_alpha;
} totals;

/* Every value finite, RGB >= 0, alpha in [0, 1]; returns the bad pixels. */
static long check_image(const float* img, const char* what, int scene, totals* t)
{
    long bad = 0;
    for (int p = 0; p < W * H; ++p) {
        const float* v = img + 4 * p;
        int ok = v[3] >= 0.0f && v[3] <= 1.0f; /* (false for NaN) */
        for (int c = 0; c < 3; ++c) ok &= isfinite(v[c]) && v[c] >= 0.0f;
        if (!ok && bad++ == 0)
            fprintf(stderr, "scene %d, %s: pixel (%d, %d) = (%g, %g, %g, %g)\n", scene, what, p % W, p / W, v[0],
                    v[1], v[2], v[3]);
        if (ok) t->max_alpha = fmax(t->max_alpha, v[3]), t->max_rgb = fmax(t->max_rgb, fmax(v[0], fmax(v[1], v[2])));
    }
    return bad;
}

/* How far a reference D may fall as the point moves away from the light by
 * rounding alone. D(x) and D(x') are two separate double computations of
 * integrals of which the second's path contains the first's. Their points
 * p = x + t d are rounded by at most ~2 eps (|x| + |t d|) per coordinate;
 * pos_err = 8 eps M sqrt(3) bounds that with M the largest coordinate or
 * path length involved. That moves (a) each of the at most n_pieces + 1
 * piece boundaries of each integral, by at most rho_max pos_err each, and
 * (b) the quadrature nodes, where the trilinear field's slope is at most
 * sqrt(3) rho_max / voxel, over a path of at most the box diagonal inside
 * the box. The compensated sums add a relative ~1e-16 per piece: 1e-12 D
 * covers it with room. */
static double ref_tolerance(const veil_grid* g, double rho_max, double M, double diag, double D)
{
    const double pos_err = 8.0 * DBL_EPSILON * M * sqrt(3.0), pieces = g->dims[0] + g->dims[1] + g->dims[2] + 1;
    return rho_max * pos_err * (4.0 * (pieces + 1) + sqrt(3.0) * diag / g->voxel) + 1e-12 * D;
}

static double max_abs3(const double v[3]) { return fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2]))); }

/* CPU ground truth at REF_POINTS random points per light, each moved
 * REF_STEPS times away from the light. Returns the failures. */
static long check_reference(const veil_scene* s, const veil_grid* g, const float* rho, int scene, totals* t)
{
    size_t nv = veil_grid_voxels(g);
    double rho_max = 0.0;
    for (size_t v = 0; v < nv; ++v) rho_max = fmax(rho_max, rho[v]);
    float lo[3], hi[3];
    veil_grid_medium_box(g, lo, hi);
    const double mid[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
    const double diag = diagonal(lo, hi), box_abs = max_abs3(mid) + diag;
    long bad = 0;
    for (size_t l = 0; l < s->light_count; ++l) {
        const veil_light* L = &s->lights[l];
        const int directional = L->type == VEIL_LIGHT_DIRECTIONAL;
        const double P[3] = {L->position[0], L->position[1], L->position[2]};
        for (int q = 0; q < REF_POINTS; ++q) {
            double x[3], u[3];
            for (int a = 0; a < 3; ++a) /* in the box, or (1 in 4) up to a box size around it */
                x[a] = chance(0.75) ? rnd_in(lo[a], hi[a]) : rnd_in(2 * lo[a] - hi[a], 2 * hi[a] - lo[a]);
            const double dl[3] = {L->direction[0], L->direction[1], L->direction[2]}, zero[3] = {0, 0, 0};
            const double d = directional ? dist3(zero, dl) : dist3(P, x); /* away from the light: u */
            for (int a = 0; a < 3; ++a) u[a] = directional ? dl[a] / d : (x[a] - P[a]) / d;
            if (!(d > 0)) rnd_unit(u);
            const double delta = g->voxel * rnd_in(0.1, 3.0);
            double prev = 0.0;
            for (int k = 0; k < REF_STEPS; ++k) {
                double xk[3];
                for (int a = 0; a < 3; ++a) xk[a] = x[a] + k * delta * u[a];
                double D = veil_ref_optical_depth(g, rho, L, xk, 0.0);
                double M = fmax(max_abs3(xk), box_abs) +
                           (directional ? dist3(xk, mid) + diag : fmax(max_abs3(P), dist3(P, xk)));
                ++t->ref_checked;
                int ok = isfinite(D) && D >= 0.0;
                double drop = prev - D, tol = ref_tolerance(g, rho_max, M, diag, prev);
                if (k > 0 && ok && !(drop <= tol)) ok = 0;
                if (ok && k > 0 && prev > 0) t->worst_ref_drop = fmax(t->worst_ref_drop, drop / prev);
                if (!ok && bad++ == 0)
                    fprintf(stderr, "scene %d, light %zu: reference D = %.17g after %.17g at step %d (tol %.3g)\n",
                            scene, l, D, prev, k, tol);
                if (isfinite(D)) t->max_D_ref = fmax(t->max_D_ref, D);
                prev = D;
            }
        }
    }
    return bad;
}

/* GPU optical depth of every light: finite and >= 0. */
static long check_opv(veil_renderer* r, const veil_scene* s, const veil_grid* g, const float* rho,
                      veil_opv_method method, int scene, totals* t, int* rejected)
{
    int n = (int)s->light_count;
    if (n == 0) return 0;
    veil_index_light ol[VEIL_MAX_LIGHTS];
    for (int l = 0; l < n; ++l) veil_light_to_index(&s->lights[l], g->dims, g->origin, g->voxel, &ol[l]);
    float st = 0.0f;
    for (int c = 0; c < 3; ++c) st = fmaxf(st, s->medium.sigma_a[c] + s->medium.sigma_s[c]);
    /* as the renderer: a step changes no tau = sigma_t D by more than the tolerance */
    veil_opv_params params = {.method = method, .tolerance = st > 0.0f ? VEIL_OPV_TAU_TOLERANCE / st : INFINITY};
    size_t nv = veil_grid_voxels(g);
    float* D = malloc((size_t)n * nv * sizeof(float));
    veil_error err = {0};
    int it = 0;
    long bad = 0;
    if (!D || veil_renderer_propagate(r, g, rho, ol, n, &params, D, &it, &err) != VEIL_OK) {
        fprintf(stderr, "scene %d: propagate rejected: %s\n", scene, D ? err.msg : "out of memory");
        *rejected = 1;
    } else {
        for (size_t v = 0; v < (size_t)n * nv; ++v) {
            if (!(isfinite(D[v]) && D[v] >= 0.0f) && bad++ == 0)
                fprintf(stderr, "scene %d: GPU D of light %zu at voxel %zu = %g\n", scene, v / nv, v % nv, D[v]);
            if (isfinite(D[v])) t->max_D_gpu = fmax(t->max_D_gpu, D[v]);
        }
    }
    free(D);
    return bad;
}

/* Renders at max_distance 0 (no limit) and three distances; checks each
 * image and that alpha never decreases with max_distance. */
static long check_renders(veil_renderer* r, const veil_scene* s, const gen_scene* gs, veil_render_opts o, int scene,
                          totals* t, long* monotone_bad, int* rejected)
{
    /* three limits spanning the medium (about o +- e/2) from the camera; 0: none */
    const double e = gs->s * sqrt(3.0), near = fmax(dist3(gs->cam, gs->o) - 0.5 * e, 0.0);
    const float limits[4] = {(float)(near + 0.05 * e), (float)(near + 0.5 * e), (float)(near + e), 0.0f};
    float* img[4] = {NULL, NULL, NULL, NULL};
    long bad = 0;
    veil_error err = {0};
    for (int k = 0; k < 4 && !*rejected; ++k) {
        o.max_distance = limits[k];
        veil_render_stats st;
        if (veil_render_scene(r, s, &o, &img[k], &st, &err) != VEIL_OK) {
            fprintf(stderr, "scene %d: render rejected: %s\n", scene, err.msg);
            *rejected = 1;
            break;
        }
        char what[64];
        snprintf(what, sizeof what, "render (max_distance %g)", limits[k]);
        bad += check_image(img[k], what, scene, t);
    }
    for (int p = 0; p < W * H && !*rejected; ++p) {
        for (int k = 0; k < 3; ++k)
            if (!(img[k][4 * p + 3] <= img[k + 1][4 * p + 3]) && (*monotone_bad)++ == 0)
                fprintf(stderr, "scene %d: pixel (%d, %d): alpha %.9g at max_distance %g > %.9g at %g\n", scene,
                        p % W, p / W, img[k][4 * p + 3], limits[k], img[k + 1][4 * p + 3], limits[k + 1]);
    }
    int opaque = !*rejected, clear = !*rejected;
    for (int p = 0; p < W * H && !*rejected; ++p) opaque &= img[3][4 * p + 3] > 0.99f, clear &= img[3][4 * p + 3] < 0.01f;
    t->opaque_scenes += opaque, t->clear_scenes += clear;
    for (int k = 0; k < 4; ++k) free(img[k]);
    return bad;
}

/* The CPU path tracer on the same scene. Returns the bad values. */
static long check_pathtracer(const veil_scene* s, int scene, totals* t)
{
    veil_pt_medium* m = NULL;
    veil_error err = {0};
    float *img = NULL, *se = NULL;
    veil_pt_stats st = {0};
    veil_pt_opts o = {.width = PT_W, .height = PT_H, .spp = 2, .max_order = 0, .seed = (uint64_t)scene, .threads = 2};
    long bad = 0;
    if (veil_pt_medium_from_scene(s, &m, &err) != VEIL_OK || veil_pt_render(m, s, &o, &img, &se, &st, &err) != VEIL_OK) {
        fprintf(stderr, "scene %d: path tracer rejected: %s\n", scene, err.msg);
        ++t->pt_rejected;
    } else {
        for (int p = 0; p < PT_W * PT_H; ++p) {
            const float *v = img + 4 * p, *e = se + 3 * p;
            int ok = v[3] >= 0.0f && v[3] <= 1.0f;
            for (int c = 0; c < 3; ++c) ok &= isfinite(v[c]) && v[c] >= 0.0f && isfinite(e[c]) && e[c] >= 0.0f;
            if (!ok && bad++ == 0)
                fprintf(stderr, "scene %d, path tracer: pixel (%d, %d) = (%g, %g, %g, %g) +- (%g, %g, %g)\n", scene,
                        p % PT_W, p / PT_W, v[0], v[1], v[2], v[3], e[0], e[1], e[2]);
            if (ok) t->pt_max_alpha = fmax(t->pt_max_alpha, v[3]);
        }
        t->pt_cut_walks += st.cut_walks, t->pt_dropped += st.dropped_samples;
        t->pt_paths += st.paths, t->pt_collisions += st.collisions;
        if (st.cut_walks || st.dropped_samples)
            fprintf(stderr, "scene %d, path tracer: %llu walks cut, %llu samples dropped\n", scene,
                    (unsigned long long)st.cut_walks, (unsigned long long)st.dropped_samples);
    }
    free(img), free(se);
    veil_pt_medium_free(m);
    return bad;
}

/* Moves the lights the generator marked onto a random voxel centre. */
static void lights_to_voxels(veil_scene* s, const gen_scene* gs, const veil_grid* g)
{
    for (size_t l = 0; l < s->light_count; ++l) {
        if (!gs->voxel_light[l]) continue;
        float c[3];
        veil_grid_center(g, (int)(rnd() * g->dims[0]), (int)(rnd() * g->dims[1]), (int)(rnd() * g->dims[2]), c);
        memcpy(s->lights[l].position, c, sizeof c);
    }
}

/* One scene; returns 1 when it failed a check. */
static int run_scene(veil_renderer* r, int scene, const sbuf* json, gen_scene* gs, totals* t)
{
    veil_scene s;
    veil_scene_volume v;
    veil_error err = {0};
    char name[32];
    snprintf(name, sizeof name, "stress-%d.json", scene);
    veil_result res = veil_scene_parse(name, json->p, json->len, &s, &err);
    if (res == VEIL_OK && (res = veil_scene_volume_open(&s, &v, &err)) != VEIL_OK) veil_scene_free(&s);
    if (res != VEIL_OK) {
        fprintf(stderr, "scene %d: rejected: %s\n", scene, err.msg);
        ++t->rejected;
        return 0;
    }
    int rejected = 0;
    float* rho = NULL;
    if (v.has_volume) {
        lights_to_voxels(&s, gs, &v.grid);
        if (veil_scene_volume_density(&v, &rho, &err) != VEIL_OK) {
            fprintf(stderr, "scene %d: density rejected: %s\n", scene, err.msg);
            rejected = 1;
        }
    }
    static const veil_opv_method methods[4] = {VEIL_OPV_JACOBI, VEIL_OPV_JACOBI_CORRECTED, VEIL_OPV_SWEEP,
                                               VEIL_OPV_SEMI_LAGRANGIAN};
    veil_render_opts o = {.seed = (uint32_t)scene,
                          .method = chance(0.6) ? VEIL_OPV_DEFAULT : methods[(int)(rnd() * 4)]};
    long img_bad = 0, mono_bad = 0, opv_bad = 0, ref_bad = 0, pt_bad = 0;
    const double t0 = veil_now_ms();
    double t1 = t0;
    if (!rejected) img_bad = check_renders(r, &s, gs, o, scene, t, &mono_bad, &rejected);
    if (!rejected && rho) {
        size_t nv = veil_grid_voxels(&v.grid);
        for (size_t i = 0; i < nv; ++i)
            if (!(isfinite(rho[i]) && rho[i] >= 0.0f) && opv_bad++ == 0)
                fprintf(stderr, "scene %d: density[%zu] = %g\n", scene, i, rho[i]);
        opv_bad += check_opv(r, &s, &v.grid, rho, o.method, scene, t, &rejected);
        t1 = veil_now_ms();
        ref_bad = check_reference(&s, &v.grid, rho, scene, t);
    } else {
        t1 = veil_now_ms();
    }
    if (!rejected && log_majorant_depth(&s, &v, rho) > log(PT_MAX_TAU_MAJ)) ++t->pt_skipped;
    else if (!rejected) pt_bad = check_pathtracer(&s, scene, t), ++t->pt_run;
    t->pt_bad += pt_bad;
    const double t2 = veil_now_ms();
    t->ms_gpu += t1 - t0;
    t->ms_cpu += t2 - t1;
    if (t2 - t0 > t->slowest_ms) t->slowest_ms = t2 - t0, t->slowest = scene;
    t->rejected += rejected, t->pixels_bad += img_bad, t->monotone_bad += mono_bad;
    t->opv_bad += opv_bad, t->ref_bad += ref_bad;
    if (!rejected) {
        const int f[F_COUNT] = {gs->cam_inside, gs->light_at_centre, gs->light_far, gs->zero_size, gs->steep_fog,
                                gs->huge_fog, gs->sigma_zero};
        for (int k = 0; k < F_COUNT; ++k) t->features[k] += f[k];
    }
    free(rho), veil_scene_volume_close(&v), veil_scene_free(&s);
    return img_bad + mono_bad + opv_bad + ref_bad + pt_bad > 0;
}

int main(int argc, char** argv)
{
    const int scenes = argc > 1 ? atoi(argv[1]) : 500;
    const uint64_t seed = argc > 2 ? strtoull(argv[2], NULL, 0) : 3; /* meets both bugs fixed in march.comp */
    const int first = argc > 3 ? atoi(argv[3]) : 0;
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer* r = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    if (!r) return check_finish();
    totals t = {0};
    sbuf json = {0};
    int dumps = 0;
    const double t0 = veil_now_ms();
    for (int i = first; i < first + scenes; ++i) {
        gen_scene gs;
        rng = seed ^ (VEIL_RNG_GAMMA * (uint64_t)(i + 1)), rnd(); /* scene i's own stream */
        gen_scene_json(&json, &gs);
        ++t.scenes;
        const uint64_t cut = t.pt_cut_walks + t.pt_dropped;
        if (run_scene(r, i, &json, &gs, &t)) {
            ++t.failed_scenes;
            if (dumps++ < MAX_DUMPS) fprintf(stderr, "scene %d failed; its JSON:\n%s\n", i, json.p);
        } else if (t.pt_cut_walks + t.pt_dropped > cut && dumps++ < MAX_DUMPS) {
            fprintf(stderr, "scene %d: path-tracer walks cut or samples dropped; its JSON:\n%s\n", i, json.p);
        }
    }
    const double ms = veil_now_ms() - t0;
    printf("stress: %d scenes in %.1f s (%.1f ms each), %d rejected, %d failed\n", t.scenes, ms / 1000.0,
           ms / (t.scenes ? t.scenes : 1), t.rejected, t.failed_scenes);
    printf("  bad pixels %ld, alpha decreasing with max_distance %ld, bad GPU D %ld, bad reference D %ld of %ld\n",
           t.pixels_bad, t.monotone_bad, t.opv_bad, t.ref_bad, t.ref_checked);
    printf("  max alpha %.9g, max rgb %.3g, max D: GPU %.3g, reference %.3g; largest relative fall of a reference "
           "D within its rounding tolerance %.3g\n",
           t.max_alpha, t.max_rgb, t.max_D_gpu, t.max_D_ref, t.worst_ref_drop);
    printf("  fully opaque images %d, fully clear images %d\n", t.opaque_scenes, t.clear_scenes);
    printf("  path tracer on %d scenes (%d skipped: majorant optical depth > %g):\n    %ld bad values, %d rejected, "
           "max alpha %.9g; %llu paths, %llu collisions, %llu walks cut, %llu samples dropped\n",
           t.pt_run, t.pt_skipped, PT_MAX_TAU_MAJ, t.pt_bad, t.pt_rejected, t.pt_max_alpha, (unsigned long long)t.pt_paths,
           (unsigned long long)t.pt_collisions, (unsigned long long)t.pt_cut_walks, (unsigned long long)t.pt_dropped);
    printf("  time: GPU renders and D %.1f s, CPU reference D and path tracer %.1f s; slowest scene %d (%.0f ms)\n",
           t.ms_gpu / 1000.0, t.ms_cpu / 1000.0, t.slowest, t.slowest_ms);
    for (int k = 0; k < F_COUNT; ++k) printf("  scenes with %s: %d\n", feature_names[k], t.features[k]);
    /* every kind of extreme was actually exercised */
    for (int k = 0; k < F_COUNT; ++k)
        CHECK(t.features[k] >= t.scenes / 50, "only %d scenes with %s", t.features[k], feature_names[k]);
    CHECK(t.pixels_bad == 0, "%ld pixels non-finite, negative or with alpha outside [0, 1]", t.pixels_bad);
    CHECK(t.monotone_bad == 0, "%ld pixels whose alpha fell as max_distance grew", t.monotone_bad);
    CHECK(t.opv_bad == 0, "%ld GPU optical depths non-finite or negative", t.opv_bad);
    CHECK(t.ref_bad == 0, "%ld reference optical depths non-finite, negative or falling", t.ref_bad);
    CHECK(t.pt_bad == 0, "%ld path-traced values non-finite, negative or with alpha outside [0, 1]", t.pt_bad);
    CHECK(t.pt_rejected * 20 <= t.pt_run, "the path tracer rejected %d of %d scenes (> 5 %%)", t.pt_rejected,
          t.pt_run);
    CHECK(t.pt_run >= t.scenes / 3, "the path tracer ran on only %d of %d scenes", t.pt_run, t.scenes);
    CHECK(t.rejected * 20 <= t.scenes, "%d of %d scenes rejected (> 5 %%): the generator makes invalid scenes",
          t.rejected, t.scenes);
    free(json.p), veil_renderer_destroy(r), veil_gl_destroy(gl);
    return check_finish();
}
