/* veil — a light's optical depth: the light-space prefix sum
 * (propagate/sun_space.h; for point lights its perspective form) against
 * the semi-Lagrangian pass on the EV's grid, run time against error.
 *
 *   sun_space [--sizes 64,128] [--media smoke,smoke-vdb,...] [--runs N] [--suns | --points]
 *
 * For each medium of bench/media.h on an N^3 grid and each light (the
 * directional light of bench/propagation.c and a second, steeper one; its
 * two point lights, inside the box and outside it),
 * each configuration fills its optical depth on the GPU; the time is the
 * median over --runs of the whole call, upload and read-back included
 * (both methods pay the same upload; the read-back of the light-space grid
 * is 4 bytes a node, the semi-Lagrangian's 16 a voxel). The error is taken
 * against the exact optical depth of reference/optical_depth.h at 3000
 * seeded random points of the medium's box (where the march reads D:
 * anywhere, not only at voxel centres), each grid read as the march reads
 * it, in double here: the semi-Lagrangian volume trilinearly; the
 * light-space grid bilinearly on the node plane towards the light plus the
 * density over the stretch back (lit_medium.glsl; a point light's through
 * veil_point_space_depth, the shader's C twin, in float). The read-back is
 * timed too: a point light's grid holds more nodes than the EV has voxels,
 * so in-frame stage times (docs/performance.md) are its fairer cost. Same metrics as
 * bench/propagation.c: sigma_t = 4 / (box width * max density), rms of the
 * relative error of D where tau_ref >= 0.05, max |exp(-tau) - exp(-tau_ref)|.
 * Exit status: 0, 77 when no GL 4.5 context can be made, 1 on errors. */
#include <epoxy/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/rng.h"
#include "gpu/gl_context.h"
#include "media.h"
#include "propagate/opv_set.h"
#include "propagate/sun_space.h"
#include "reference/optical_depth.h"

#define SAMPLES 3000
#define TAU_FLOOR 0.05

static const char* const medium_names[MEDIUM_COUNT] = {"homogeneous", "rbf-fog", "smoke", "smoke-vdb"};

typedef struct config {
    const char* name;
    int light_space; /* 0: semi-Lagrangian on the grid */
    float across, along;
    int panels;
    int points;      /* 1: for point lights (the perspective grid), 0: for suns, -1: both */
    int pieces;      /* point lights: the stretch back's pieces, 0: veil_point_space_pieces */
} config;

static const config configs[] = {
    {"semi-lagrangian", 0, 0, 0, 0, -1, 0},
    {"perspective as planned (default rung)", 1, 0.0f, 2.0f, 1, 1, 0},
    {"perspective 1.4/2 (draft's least)", 1, 1.4f, 2.0f, 1, 1, 0},
    {"perspective 1.09/2", 1, 1.09f, 2.0f, 1, 1, 0},
    {"perspective 0.875/2", 1, 0.875f, 2.0f, 1, 1, 0},
    {"perspective 0.7/2 (default's least)", 1, 0.7f, 2.0f, 1, 1, 0},
    {"perspective 0.7/2, 1 piece", 1, 0.7f, 2.0f, 1, 1, 1},
    {"perspective 0.7/2, pieces <= 1 voxel", 1, 0.7f, 2.0f, 1, 1, 4},
    {"perspective 0.7/4", 1, 0.7f, 4.0f, 1, 1, 0},
    {"perspective 0.5/2", 1, 0.5f, 2.0f, 1, 1, 0},
    {"perspective 0.35/2", 1, 0.35f, 2.0f, 1, 1, 0},
    {"light-space 1/1", 1, 1.0f, 1.0f, 1, 0, 0},
    {"light-space 1/1, 2 panels", 1, 1.0f, 1.0f, 2, 0, 0},
    {"light-space 1/4", 1, 1.0f, 4.0f, 1, 0, 0},
    {"light-space 0.7/4", 1, 0.7f, 4.0f, 1, 0, 0},
    {"light-space 0.5/1", 1, 0.5f, 1.0f, 1, 0, 0},
    {"light-space 0.5/4", 1, 0.5f, 4.0f, 1, 0, 0},
    {"light-space 0.35/4", 1, 0.35f, 4.0f, 1, 0, 0},
};
#define CONFIGS (int)(sizeof configs / sizeof configs[0])

/* D at world x as the march reads a light-space grid (render/shaders/
 * lit_medium.glsl), in double: the bilinear lookup on the node plane just
 * towards the light, plus the density over the stretch back to x, midpoint
 * rule in pieces of at most a voxel. */
static double lookup(const veil_grid* g, const float* rho, const veil_sun_space* s, const float* D, const double x[3],
                     const float travel[3])
{
    float m[3][4];
    veil_sun_space_to_texture(g, s, m);
    double q[3];
    for (int r = 0; r < 3; ++r) {
        double t = m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2] + m[r][3];
        q[r] = t * s->nodes[r] - 0.5;
        q[r] = q[r] < 0 ? 0 : q[r] > s->nodes[r] - 1 ? s->nodes[r] - 1 : q[r];
    }
    const float* c = s->axis[2];
    double along = sqrt((double)c[0] * c[0] + (double)c[1] * c[1] + (double)c[2] * c[2]);
    double back = (q[2] - floor(q[2])) * along * g->voxel; /* m */
    int k = (int)floor(q[2]), i0[2], i1[2];
    double f[2];
    for (int r = 0; r < 2; ++r) {
        double fl = floor(q[r]);
        i0[r] = (int)fl;
        i1[r] = i0[r] + 1 < s->nodes[r] ? i0[r] + 1 : i0[r];
        f[r] = q[r] - fl;
    }
    double sum = 0.0;
    for (int corner = 0; corner < 4; ++corner) {
        int ix = corner & 1 ? i1[0] : i0[0], iy = corner & 2 ? i1[1] : i0[1];
        double w = (corner & 1 ? f[0] : 1 - f[0]) * (corner & 2 ? f[1] : 1 - f[1]);
        sum += w * D[((size_t)k * s->nodes[1] + iy) * s->nodes[0] + ix];
    }
    /* the stretch's part in the medium's box, as the shader clips it */
    float blo[3], bhi[3];
    veil_grid_medium_box(g, blo, bhi);
    for (int a = 0; a < 3; ++a)
        if (travel[a] != 0.0f) {
            double exit = ((travel[a] < 0 ? bhi[a] : blo[a]) - x[a]) / -travel[a];
            back = exit < back ? (exit > 0 ? exit : 0) : back;
        }
    int pieces = (int)ceil(along);
    double piece = back / pieces;
    for (int p = 0; p < pieces; ++p) {
        double y[3];
        for (int a = 0; a < 3; ++a) y[a] = x[a] - travel[a] * piece * (p + 0.5);
        sum += veil_ev_sample(g, rho, y) * piece;
    }
    return sum;
}

/* D at world x (in the box) from a point light's perspective grid, as the
 * march reads it: veil_point_space_depth (the shader's C twin), the
 * stretch back clipped to the path's part in the box (to the light, or to
 * where the path leaves the box). */
static double lookup_point(const veil_grid* g, const float* rho, const veil_sun_space* s, const float* D,
                           const double x[3], const float light[3], int pieces)
{
    float blo[3], bhi[3], y[3];
    veil_grid_medium_box(g, blo, bhi);
    double to[3], dist = 0.0;
    for (int a = 0; a < 3; ++a) to[a] = light[a] - x[a], dist += to[a] * to[a];
    dist = sqrt(dist);
    double room = dist;
    for (int a = 0; a < 3; ++a) {
        to[a] /= dist;
        y[a] = (float)((x[a] - g->origin[a]) / g->voxel - 0.5);
        if (to[a] != 0.0) {
            double exit = ((to[a] > 0 ? bhi[a] : blo[a]) - x[a]) / to[a];
            room = exit < room ? (exit > 0 ? exit : 0) : room;
        }
    }
    return veil_point_space_depth(g, rho, s, D, y, (float)room, pieces > 0 ? pieces : veil_point_space_pieces(s));
}

/* Trilinear lookup of an OPV on the EV's grid at world x (clamped like the texture). */
static double lookup_grid(const veil_grid* g, const float* D, const double x[3])
{
    int i0[3], i1[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        double q = (x[a] - g->origin[a]) / g->voxel - 0.5;
        q = q < 0 ? 0 : q > g->dims[a] - 1 ? g->dims[a] - 1 : q;
        double fl = floor(q);
        i0[a] = (int)fl;
        i1[a] = i0[a] + 1 < g->dims[a] ? i0[a] + 1 : i0[a];
        f[a] = q - fl;
    }
    double sum = 0.0;
    for (int c = 0; c < 8; ++c) {
        int ix = c & 1 ? i1[0] : i0[0], iy = c & 2 ? i1[1] : i0[1], iz = c & 4 ? i1[2] : i0[2];
        double w = (c & 1 ? f[0] : 1 - f[0]) * (c & 2 ? f[1] : 1 - f[1]) * (c & 4 ? f[2] : 1 - f[2]);
        sum += w * D[((size_t)iz * g->dims[1] + iy) * g->dims[0] + ix];
    }
    return sum;
}

static int cmp_double(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

int main(int argc, char** argv)
{
    int sizes[8] = {64, 128}, n_sizes = 2, runs = 3, only_suns = 0, only_points = 0;
    int use[MEDIUM_COUNT] = {1, 1, 1, 1};
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--sizes") && i + 1 < argc) {
            n_sizes = 0;
            for (char* t = strtok(argv[++i], ","); t && n_sizes < 8; t = strtok(NULL, ",")) sizes[n_sizes++] = atoi(t);
        } else if (!strcmp(argv[i], "--suns")) {
            only_suns = 1;
        } else if (!strcmp(argv[i], "--points")) {
            only_points = 1;
        } else if (!strcmp(argv[i], "--runs") && i + 1 < argc) {
            runs = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--media") && i + 1 < argc) {
            memset(use, 0, sizeof use);
            for (char* t = strtok(argv[++i], ","); t; t = strtok(NULL, ","))
                for (int m = 0; m < MEDIUM_COUNT; ++m)
                    if (!strcmp(t, medium_names[m])) use[m] = 1;
        } else {
            fprintf(stderr, "usage: sun_space [--sizes 64,128] [--media a,b] [--runs N] [--suns | --points]\n");
            return 2;
        }
    }
    if (runs < 1 || runs > 99) runs = 3;
    veil_error err;
    veil_gl* gl = NULL;
    veil_result res = veil_gl_create(&(veil_gl_desc){0}, &gl, &err);
    if (res != VEIL_OK) {
        fprintf(stderr, "sun_space: skipped: %s\n", err.msg);
        return 77;
    }
    veil_opv_set* set = NULL;
    if (veil_opv_set_create(&set, &err) != VEIL_OK) {
        fprintf(stderr, "sun_space: %s\n", err.msg);
        return 1;
    }
    GLint max_axis = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max_axis);
    const float suns[2][3] = {{-0.5f, -0.6f, -0.62f}, {0.3f, -1.0f, 0.2f}};
    /* bench/propagation.c's point lights: inside the box, and outside it */
    const float points[2][3] = {{0.0637f, 0.1437f, -0.0533f}, {-2.83f, 1.61f, 1.17f}};
    const char* const light_names[4] = {"sun 0", "sun 1", "point in", "point out"};
    printf("| medium | grid | light | method | nodes (M) | time (ms) | rms rel. error of D | max |Δ exp(−τ)| |\n");
    printf("|---|---|---|---|---:|---:|---:|---:|\n");
    int status = 0;
    for (int si = 0; si < n_sizes && status == 0; ++si)
        for (int med = 0; med < MEDIUM_COUNT && status == 0; ++med) {
            if (!use[med]) continue;
            veil_grid g = bench_grid(sizes[si]);
            float* rho = make_medium(med, &g, &err);
            if (!rho) {
                fprintf(stderr, "sun_space: %s: %s (skipped)\n", medium_names[med], err.msg);
                continue;
            }
            float rmax = 0.0f;
            size_t nv = veil_grid_voxels(&g);
            for (size_t v = 0; v < nv; ++v) rmax = rho[v] > rmax ? rho[v] : rmax;
            double sigma_t = 4.0 / (BOX_WIDTH * (rmax > 0 ? rmax : 1));
            uint64_t rng = 12345;
            double(*samples)[3] = malloc(SAMPLES * sizeof *samples);
            float lo[3], hi[3];
            veil_grid_medium_box(&g, lo, hi);
            double* dref = malloc(SAMPLES * sizeof *dref);
            float* grid_d = malloc(nv * sizeof *grid_d);
            for (int li = only_points ? 2 : 0; li < (only_suns ? 2 : 4) && status == 0; ++li) {
                const int point = li >= 2;
                veil_light l = {.type = point ? VEIL_LIGHT_POINT : VEIL_LIGHT_DIRECTIONAL, .color = {1, 1, 1}};
                if (point) {
                    for (int a = 0; a < 3; ++a) l.position[a] = points[li - 2][a];
                } else {
                    const float* d = suns[li];
                    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    for (int a = 0; a < 3; ++a) l.direction[a] = (float)(d[a] / len);
                }
                for (int s = 0; s < SAMPLES; ++s) {
                    for (int a = 0; a < 3; ++a) samples[s][a] = lo[a] + (hi[a] - lo[a]) * veil_rng_double53(&rng);
                    dref[s] = veil_ref_optical_depth(&g, rho, &l, samples[s], 1.0);
                }
                veil_index_light ol;
                veil_light_to_index(&l, g.dims, g.origin, g.voxel, &ol);
                for (int c = 0; c < CONFIGS && status == 0; ++c) {
                    const config* cf = &configs[c];
                    if (cf->points >= 0 && cf->points != point) continue;
                    veil_sun_space sp;
                    float* D = grid_d;
                    if (cf->light_space) {
                        veil_result made = VEIL_OK;
                        if (point && cf->across == 0.0f) { /* the spacing the renderer's plan picks */
                            veil_opv_params dp = {.method = VEIL_OPV_LIGHT_SPACE};
                            veil_index_light pl;
                            veil_opv_sun want[VEIL_MAX_SUNS];
                            uint64_t keys[VEIL_MAX_SUNS];
                            if (veil_opv_plan_suns(&g, 1, &l, 1, &dp, max_axis, &pl, want, keys) == 1)
                                sp = want[0].space;
                            else
                                made = veil_fail(&err, VEIL_ERR_LIMIT, "the plan gave the light no grid");
                        } else
                            made =
                            point ? veil_point_space_make(&g, ol.v, cf->across, cf->along, cf->panels, max_axis,
                                                          VEIL_SUN_MAX_NODES, &sp, &err)
                                  : veil_sun_space_make(&g, l.direction, cf->across, cf->along, cf->panels, max_axis,
                                                        VEIL_SUN_MAX_NODES, &sp, &err);
                        if (made != VEIL_OK) {
                            fprintf(stderr, "sun_space: %s\n", err.msg);
                            continue;
                        }
                        D = malloc(veil_sun_space_nodes(&sp) * sizeof *D);
                    }
                    double times[99];
                    for (int r = 0; r < runs && status == 0; ++r) {
                        glFinish();
                        double t0 = veil_now_ms();
                        int it = 0;
                        veil_opv_params params = {.method = VEIL_OPV_SEMI_LAGRANGIAN};
                        res = cf->light_space ? veil_opv_set_sun_readback(set, &g, rho, &sp, 1, D, &err)
                                              : veil_opv_set_propagate_readback(set, &g, rho, &ol, 1, &params, D, &it, &err);
                        glFinish();
                        times[r] = veil_now_ms() - t0;
                        if (res != VEIL_OK) {
                            fprintf(stderr, "sun_space: %s\n", err.msg);
                            status = 1;
                        }
                    }
                    if (status) break;
                    qsort(times, (size_t)runs, sizeof times[0], cmp_double);
                    double sum2 = 0.0, max_t = 0.0;
                    size_t counted = 0;
                    for (int s = 0; s < SAMPLES; ++s) {
                        double d = !cf->light_space ? lookup_grid(&g, D, samples[s])
                                   : point ? lookup_point(&g, rho, &sp, D, samples[s], l.position, cf->pieces)
                                           : lookup(&g, rho, &sp, D, samples[s], l.direction);
                        double dt = fabs(exp(-sigma_t * d) - exp(-sigma_t * dref[s]));
                        max_t = dt > max_t ? dt : max_t;
                        if (sigma_t * dref[s] >= TAU_FLOOR) {
                            double e = (d - dref[s]) / dref[s];
                            sum2 += e * e;
                            ++counted;
                        }
                    }
                    char name[96];
                    snprintf(name, sizeof name, cf->light_space && point && cf->across == 0.0f ? "%s: %.3g/%g" : "%s",
                             cf->name, (double)sp.across, (double)sp.dz);
                    printf("| %s | %d³ | %s | %s | %.2f | %.0f | %.3f %% | %.1e |\n", medium_names[med], sizes[si], light_names[li],
                           name, cf->light_space ? veil_sun_space_nodes(&sp) / 1e6 : nv / 1e6, times[runs / 2],
                           counted ? 100.0 * sqrt(sum2 / counted) : NAN, max_t);
                    fflush(stdout);
                    if (cf->light_space) free(D);
                }
            }
            free(samples);
            free(dref);
            free(grid_d);
            free(rho);
        }
    veil_opv_set_destroy(set);
    veil_gl_destroy(gl);
    return status;
}
