/* A sun's light-space grid (propagate/sun_space.h), C twin.
 *
 * 1. Geometry: the axes are orthogonal, `across` and `along` voxels long,
 *    the third along the light's travel; every corner of the medium's box
 *    lies inside the nodes; the world -> texture map sends each node to its
 *    texel centre. Grids over the node limit and absurd inputs are refused.
 * 2. Exactness on a linear field. Trilinear interpolation reproduces a
 *    linear density, which is linear along any line, so each clipped
 *    Simpson panel is exact and D at every node must equal the exact
 *    optical depth (reference/optical_depth.h) up to float rounding:
 *      - the running sum: a relative 2^-24 per step of the prefix and a few
 *        per panel, so (nodes_c + 8) 2^-23 of D;
 *      - the column's entry and exit (float clip, positions of magnitude
 *        <= 2^9 voxels): 2^9 2^-24 = 3e-5 node steps at each end, each
 *        worth at most rho_max * step of D: 1e-4 rho_max step in all.
 * 3. Second order on a field with kinks. A trilinear field along a line is
 *    one cubic between voxel-centre planes, so Simpson is exact except in
 *    the panels holding a kink (a jump of the derivative), each off by
 *    O(w^2) for panels w long; the kinks a path crosses are fixed, so the
 *    error falls as w^2: 4x per halving. Only on average: each kink's
 *    constant depends on where it falls in its panel, which a halving
 *    moves, so single halvings scatter around 4 (3.0 to 6.5 measured here).
 *    Asked: at least 2.5x from 1 to 2 panels and 8x from 1 to 4 (16
 *    expected); first order would give 2x and 4x.
 * 4. The plan (veil_opv_plan_suns): only the light-space method makes
 *    grids, for the first VEIL_MAX_SUNS suns, point and spot lights; a
 *    grid over its node budget or the memory allowed is widened across the
 *    light until it fits, and a light whose grid cannot fit stays on the
 *    EV's grid.
 * 5. A point light's perspective grid (the faces of a cube around it), for
 *    lights inside the box, beside a face, off a corner and far away:
 *    every point of the box lies on a face that is present, inside its
 *    window of columns and its planes, where neighbouring columns are at
 *    most `across` voxels apart (du z <= across); node (i, j, k) of face f
 *    lies on the ray from the light through (u0 + i du, v0 + j du) at depth
 *    z0 + k dz; plane 0 is at the light or before the whole box.
 * 6. Exactness on a linear field, as 2: D at every node of every face
 *    equals the exact integral from the light to the node within the same
 *    rounding bound (the column's step is its own: dz |d|).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "support/check.h"
#include "support/puffs.h"
#include "propagate/opv_set.h"
#include "propagate/sun_space.h"
#include "reference/optical_depth.h"

static const float dirs[][3] = {{0.0f, -1.0f, 0.0f}, {-0.5f, -0.6f, -0.62f}, {0.3f, -1.0f, 0.2f},
                                {1.0f, 0.0f, 0.0f},  {-0.7f, 0.1f, 0.7f}};
#define NDIRS (int)(sizeof dirs / sizeof dirs[0])

static double len3(const float v[3]) { return sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]); }

static void node_world(const veil_grid* g, const veil_sun_space* s, int i, int j, int k, double x[3])
{
    for (int a = 0; a < 3; ++a)
        x[a] = g->origin[a] +
               ((double)s->origin[a] + i * (double)s->axis[0][a] + j * (double)s->axis[1][a] + k * (double)s->axis[2][a] +
                0.5) * g->voxel;
}

static void test_geometry(void)
{
    veil_grid g = {.dims = {24, 20, 28}, .origin = {-1.0f, 0.5f, 2.0f}, .voxel = 0.1f};
    for (int d = 0; d < NDIRS; ++d) {
        veil_sun_space s;
        veil_error err = {0};
        veil_result r = veil_sun_space_make(&g, dirs[d], 0.7f, 2.5f, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err);
        CHECK(r == VEIL_OK, "dir %d: %s", d, err.msg);
        if (r != VEIL_OK) continue;
        CHECK(fabs(len3(s.axis[0]) - 0.7) < 1e-6 && fabs(len3(s.axis[1]) - 0.7) < 1e-6 && fabs(len3(s.axis[2]) - 2.5) < 1e-6,
              "dir %d: axis lengths %g %g %g", d, len3(s.axis[0]), len3(s.axis[1]), len3(s.axis[2]));
        for (int p = 0; p < 3; ++p)
            for (int q = p + 1; q < 3; ++q) {
                double dot = 0;
                for (int a = 0; a < 3; ++a) dot += (double)s.axis[p][a] * s.axis[q][a];
                CHECK(fabs(dot) < 1e-6 * len3(s.axis[p]) * len3(s.axis[q]), "dir %d: axes %d, %d not orthogonal", d, p, q);
            }
        double along = 0;
        for (int a = 0; a < 3; ++a) along += s.axis[2][a] * dirs[d][a];
        CHECK(along > (1 - 1e-6) * 2.5 * len3(dirs[d]), "dir %d: the third axis is not the travel direction", d);
        CHECK(s.panels == 3, "dir %d: %d panels (a step of 2.5 voxels needs 3)", d, s.panels);
        float m[3][4];
        veil_sun_space_to_texture(&g, &s, m);
        for (int corner = 0; corner < 8; ++corner) { /* the box's corners inside the nodes */
            double x[3];
            for (int a = 0; a < 3; ++a) x[a] = g.origin[a] + ((corner >> a & 1 ? g.dims[a] - 1 : 0) + 0.5) * g.voxel;
            for (int row = 0; row < 3; ++row) {
                double node = (m[row][0] * x[0] + m[row][1] * x[1] + m[row][2] * x[2] + m[row][3]) * s.nodes[row] - 0.5;
                CHECK(node >= -1e-3 && node <= s.nodes[row] - 1 + 1e-3, "dir %d: corner %d at node %g of %d on axis %d", d,
                      corner, node, s.nodes[row], row);
            }
        }
        const int probe[3][3] = {{0, 0, 0}, {s.nodes[0] - 1, 1, s.nodes[2] - 1}, {2, s.nodes[1] - 1, 3}};
        for (int p = 0; p < 3; ++p) { /* nodes land on their texel centres */
            double x[3];
            node_world(&g, &s, probe[p][0], probe[p][1], probe[p][2], x);
            for (int row = 0; row < 3; ++row) {
                double node = (m[row][0] * x[0] + m[row][1] * x[1] + m[row][2] * x[2] + m[row][3]) * s.nodes[row] - 0.5;
                CHECK(fabs(node - probe[p][row]) < 1e-3, "dir %d: node %d maps to %g on axis %d", d, probe[p][row], node, row);
            }
        }
    }
    veil_sun_space s;
    veil_error err = {0};
    CHECK(veil_sun_space_make(&g, dirs[1], 0.5f, 1.0f, 1, 2048, 1000, &s, &err) == VEIL_ERR_LIMIT &&
              strstr(err.msg, "nodes"), "node limit: %s", err.msg);
    CHECK(veil_sun_space_make(&g, dirs[1], 0.5f, 1.0f, 1, 16, VEIL_SUN_MAX_NODES, &s, &err) == VEIL_ERR_LIMIT,
          "axis limit");
    const float zero[3] = {0, 0, 0}, nan3[3] = {NAN, 0, 1};
    CHECK(veil_sun_space_make(&g, zero, 1, 1, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err) == VEIL_ERR_INVALID, "zero direction");
    CHECK(veil_sun_space_make(&g, nan3, 1, 1, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err) == VEIL_ERR_INVALID, "NaN direction");
    CHECK(veil_sun_space_make(&g, dirs[1], 0, 1, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err) == VEIL_ERR_INVALID, "zero spacing");
    CHECK(veil_sun_space_make(&g, dirs[1], 1, INFINITY, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err) == VEIL_ERR_INVALID,
          "infinite spacing");
}

/* The rms and largest |D - exact| over every node of a sun's grid. */
static void node_errors(const veil_grid* g, const float* rho, const float dir[3], float across, float along, int panels,
                        double* rms, double* worst_rel, double* bound_ratio)
{
    veil_sun_space s;
    veil_error err = {0};
    *rms = *worst_rel = *bound_ratio = NAN;
    if (veil_sun_space_make(g, dir, across, along, panels, 4096, VEIL_SUN_MAX_NODES, &s, &err) != VEIL_OK) {
        CHECK(0, "%s", err.msg);
        return;
    }
    float* D = malloc(veil_sun_space_nodes(&s) * sizeof *D);
    veil_sun_space_cpu(g, rho, &s, D);
    veil_light l = {.type = VEIL_LIGHT_DIRECTIONAL};
    memcpy(l.direction, dir, sizeof l.direction);
    float rmax = 0;
    for (size_t v = 0; v < veil_grid_voxels(g); ++v) rmax = fmaxf(rmax, rho[v]);
    double step = len3(s.axis[2]) * g->voxel, sum2 = 0;
    size_t n = 0;
    *worst_rel = *bound_ratio = 0;
    for (int k = 0; k < s.nodes[2]; ++k)
        for (int j = 0; j < s.nodes[1]; ++j)
            for (int i = 0; i < s.nodes[0]; ++i) {
                double x[3];
                node_world(g, &s, i, j, k, x);
                double ref = veil_ref_optical_depth(g, rho, &l, x, 1.0);
                double d = D[((size_t)k * s.nodes[1] + j) * s.nodes[0] + i], e = fabs(d - ref);
                double bound = (s.nodes[2] + 8) * 0x1p-23 * ref + 1e-4 * rmax * step;
                sum2 += e * e;
                ++n;
                if (ref > 0) *worst_rel = fmax(*worst_rel, e / ref);
                *bound_ratio = fmax(*bound_ratio, e / bound);
            }
    *rms = sqrt(sum2 / (double)n);
    free(D);
}

static void test_linear_exact(void)
{
    veil_grid g = {.dims = {24, 20, 28}, .origin = {-1.0f, 0.5f, 2.0f}, .voxel = 0.1f};
    float* rho = malloc(veil_grid_voxels(&g) * sizeof *rho);
    for (int k = 0; k < g.dims[2]; ++k)
        for (int j = 0; j < g.dims[1]; ++j)
            for (int i = 0; i < g.dims[0]; ++i)
                rho[((size_t)k * g.dims[1] + j) * g.dims[0] + i] = 1.0f + 0.05f * i + 0.03f * j - 0.02f * k;
    for (int d = 0; d < NDIRS; ++d)
        for (int p = 1; p <= 2; ++p) {
            double rms, rel, ratio;
            node_errors(&g, rho, dirs[d], 0.8f, 1.0f + 0.5f * p, p, &rms, &rel, &ratio);
            CHECK(ratio <= 1.0, "linear field, dir %d, %d panels: error %.3g of the rounding bound (worst relative %.3g)", d,
                  p, ratio, rel);
        }
    free(rho);
}

static void test_second_order(void)
{
    /* three Gaussian puffs sampled at the voxels, trilinear between: kinks at every voxel plane */
    veil_grid g = {.dims = {30, 26, 22}, .origin = {0, 0, 0}, .voxel = 0.05f};
    const puff pf[3] = {{{9, 10, 8}, 2.0}, {{20, 14, 12}, 1.5}, {{14, 18, 15}, 2.5}};
    float rmax;
    float* rho = puffs_density(&g, pf, 0, &rmax);
    for (int d = 1; d < 3; ++d) {
        double rms[3], rel, ratio;
        for (int p = 0; p < 3; ++p) node_errors(&g, rho, dirs[d], 1.0f, 1.0f, 1 << p, &rms[p], &rel, &ratio);
        printf("puffs, dir %d: rms |D - exact| with 1, 2, 4 panels: %.3g, %.3g, %.3g\n", d, rms[0], rms[1], rms[2]);
        CHECK(rms[1] * 2.5 <= rms[0] && rms[2] * 8 <= rms[0], "dir %d: not second order: %.3g, %.3g, %.3g", d, rms[0],
              rms[1], rms[2]);
    }
    free(rho);
}

static void test_plan(void)
{
    veil_grid g = {.dims = {64, 64, 64}, .origin = {0, 0, 0}, .voxel = 0.1f};
    veil_light lights[7] = {{0}};
    for (int l = 0; l < 7; ++l) {
        lights[l].type = l == 2 ? VEIL_LIGHT_POINT : VEIL_LIGHT_DIRECTIONAL;
        lights[l].direction[0] = 0.2f * l - 0.5f, lights[l].direction[1] = -1.0f, lights[l].direction[2] = 0.3f;
        lights[l].position[0] = 8.0f, lights[l].position[1] = 3.0f, lights[l].position[2] = -2.0f; /* beside the box */
        lights[l].color[0] = lights[l].color[1] = lights[l].color[2] = 1.0f;
    }
    veil_index_light ol[7];
    veil_opv_sun want[VEIL_MAX_SUNS];
    uint64_t keys[VEIL_MAX_SUNS];
    veil_opv_params p = {.method = VEIL_OPV_SEMI_LAGRANGIAN};
    CHECK(veil_opv_plan_suns(&g, 1, lights, 7, &p, 2048, ol, want, keys) == 0 && !ol[0].elsewhere,
          "semi-lagrangian: no grids");
    p.method = VEIL_OPV_LIGHT_SPACE;
    int n = veil_opv_plan_suns(&g, 1, lights, 7, &p, 2048, ol, want, keys);
    CHECK(n == VEIL_MAX_SUNS, "%d grids for 7 lights (the first %d get one)", n, VEIL_MAX_SUNS);
    const int expect[7] = {1, 1, 1, 1, 0, 0, 0}; /* light 2, a point light, too */
    for (int l = 0; l < 7; ++l) CHECK(ol[l].elsewhere == expect[l], "light %d: elsewhere %d", l, ol[l].elsewhere);
    for (int k = 0; k < n; ++k) {
        CHECK(want[k].light == k, "grid %d serves light %d", k, want[k].light);
        CHECK(want[k].space.perspective == (k == 2), "grid %d: perspective %d", k, want[k].space.perspective);
        /* a point light's grid starts VEIL_POINT_ACROSS_SCALE times wider (and this one, 16-20 voxels off
         * two faces, may widen further to keep within VEIL_SUN_NODES_PER_VOXEL: its columns crowd near it) */
        CHECK(k == 2 ? want[k].space.across >= VEIL_POINT_ACROSS_SCALE * VEIL_SUN_DEFAULT_ACROSS * (1 - 1e-6)
                     : want[k].space.across == VEIL_SUN_DEFAULT_ACROSS,
              "grid %d: spacing %g", k, want[k].space.across);
        if (k != 2)
            CHECK(fabs(len3(want[k].space.axis[0]) - VEIL_SUN_DEFAULT_ACROSS) < 1e-6, "grid %d: spacing %g", k,
                  len3(want[k].space.axis[0]));
    }
    /* two nodes a voxel for each of the four suns that may get a grid: the spacing widens to fit */
    p.sun_bytes = 4.0 * VEIL_MAX_SUNS * 2 * (double)veil_grid_voxels(&g);
    n = veil_opv_plan_suns(&g, 1, lights, 7, &p, 2048, ol, want, keys);
    CHECK(n == VEIL_MAX_SUNS, "%d grids under the memory allowance", n);
    int widened = 0;
    for (int k = 0; k < n; ++k) {
        size_t nodes = veil_sun_space_nodes(&want[k].space);
        CHECK(nodes <= 2 * veil_grid_voxels(&g), "grid %d: %zu nodes (at most %zu), spacing %g", k, nodes,
              2 * veil_grid_voxels(&g), want[k].space.across);
        widened += want[k].space.across > VEIL_SUN_DEFAULT_ACROSS + 1e-6;
    }
    CHECK(widened >= 1, "no grid was widened (the first needs 742 482 nodes at the default spacing)");
    p.sun_bytes = 1.0; /* nothing fits: every sun stays on the EV's grid */
    n = veil_opv_plan_suns(&g, 1, lights, 7, &p, 2048, ol, want, keys);
    CHECK(n == 0 && !ol[0].elsewhere && !ol[1].elsewhere, "no memory: %d grids", n);
}

/* Light positions (index coordinates) for grid g of test_point_*: inside,
 * beside a face, off a corner, far away, on a face. */
static const float point_at[5][3] = {{10.3f, 7.2f, 12.9f}, {-6.0f, 9.5f, 13.0f}, {-5.0f, 26.0f, -7.5f},
                                     {150.0f, -80.0f, 40.0f}, {23.0f, 4.0f, 9.0f}};

static void test_point_geometry(void)
{
    veil_grid g = {.dims = {24, 20, 28}, .origin = {-1.0f, 0.5f, 2.0f}, .voxel = 0.1f};
    uint64_t rng = 7;
    for (int L = 0; L < 5; ++L) {
        veil_sun_space s;
        veil_error err = {0};
        const float across = 0.7f, dz = 2.5f;
        veil_result r = veil_point_space_make(&g, point_at[L], across, dz, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err);
        CHECK(r == VEIL_OK, "light %d: %s", L, err.msg);
        if (r != VEIL_OK) continue;
        CHECK(s.perspective && s.dz == dz && s.across == across, "light %d: the grid's form", L);
        int faces = 0, planes = 0;
        for (int f = 0; f < 6; ++f) {
            const veil_point_face* F = &s.face[f];
            if (!F->nz) continue;
            ++faces;
            CHECK(F->first == planes, "light %d face %d: first plane %d, %d before it", L, f, F->first, planes);
            planes += F->nz;
            CHECK(F->nu <= s.nodes[0] && F->nv <= s.nodes[1], "light %d face %d: %dx%d columns in %dx%d", L, f, F->nu,
                  F->nv, s.nodes[0], s.nodes[1]);
            CHECK(F->u0 >= -1.0f && F->v0 >= -1.0f && F->u0 <= 1.0f && F->v0 <= 1.0f && F->du > 0.0f,
                  "light %d face %d: window from (%g, %g), du %g", L, f, F->u0, F->v0, F->du);
            float fr[6][3];
            veil_sun_space_columns(&s, f, fr);
            const int a = f / 2, a1 = (a + 1) % 3, a2 = (a + 2) % 3;
            const int probe[3][3] = {{0, 0, 0}, {F->nu - 1, 1, F->nz - 1}, {F->nu / 2, F->nv - 1, F->nz / 2}};
            for (int p = 0; p < 3; ++p) { /* the node on its ray, at its depth */
                double x[3], w[3];
                for (int q = 0; q < 3; ++q) {
                    double step = fr[3][q] + ((double)probe[p][0] * fr[4][q] + (double)probe[p][1] * fr[5][q]);
                    x[q] = fr[0][q] + probe[p][0] * (double)fr[1][q] + probe[p][1] * (double)fr[2][q] + probe[p][2] * step;
                    w[q] = x[q] - point_at[L][q];
                }
                double z = (f % 2 ? -1 : 1) * w[a], zk = F->z0 + (double)probe[p][2] * dz;
                double u = F->u0 + probe[p][0] * (double)F->du, v = F->v0 + probe[p][1] * (double)F->du;
                CHECK(fabs(z - zk) <= 1e-4 * (1 + zk), "light %d face %d: node %d at depth %g, not %g", L, f, p, z, zk);
                CHECK(fabs(w[a1] - u * zk) <= 1e-4 * (1 + zk) && fabs(w[a2] - v * zk) <= 1e-4 * (1 + zk),
                      "light %d face %d: node %d off its ray", L, f, p);
            }
        }
        CHECK(faces >= 1 && planes == s.nodes[2], "light %d: %d faces, %d planes of %d", L, faces, planes, s.nodes[2]);
        CHECK((L == 0 || L == 4) ? faces == 6 || faces == 5 : faces <= 5, "light %d: %d faces", L, faces);
        for (int t = 0; t < 20000; ++t) { /* points of the box: on a face present, inside its window and planes */
            float y[3], w[3], z, u, v;
            for (int q = 0; q < 3; ++q) y[q] = (float)((g.dims[q] - 1) * veil_rng_double53(&rng));
            if (t < 8)
                for (int q = 0; q < 3; ++q) y[q] = t >> q & 1 ? (float)(g.dims[q] - 1) : 0.0f; /* the corners */
            for (int q = 0; q < 3; ++q) w[q] = y[q] - point_at[L][q];
            int f = veil_point_face_of(w, &z, &u, &v);
            const veil_point_face* F = &s.face[f];
            if (z < 1e-3f) continue; /* at the light itself */
            const float tol = 1e-4f;
            int ok = F->nz > 0 && u >= F->u0 - tol && v >= F->v0 - tol && u <= F->u0 + (float)(F->nu - 1) * F->du + tol &&
                     v <= F->v0 + (float)(F->nv - 1) * F->du + tol && z >= F->z0 - tol &&
                     z <= F->z0 + (float)(F->nz - 1) * dz + tol && F->du * z <= across * (1 + tol);
            CHECK(ok, "light %d: box point (%g, %g, %g) on face %d (%d planes) at u %g v %g z %g outside it", L, y[0], y[1],
                  y[2], f, F->nz, u, v, z);
            if (!ok) break;
        }
    }
    veil_sun_space s;
    veil_error err = {0};
    const float nan3[3] = {NAN, 0, 1};
    CHECK(veil_point_space_make(&g, nan3, 1, 1, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err) == VEIL_ERR_INVALID, "NaN light");
    CHECK(veil_point_space_make(&g, point_at[0], 0, 1, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err) == VEIL_ERR_INVALID,
          "zero spacing");
    CHECK(veil_point_space_make(&g, point_at[0], 0.5f, 1, 1, 2048, 1000, &s, &err) == VEIL_ERR_LIMIT &&
              strstr(err.msg, "nodes"), "node limit: %s", err.msg);
    CHECK(veil_point_space_make(&g, point_at[0], 0.5f, 1, 1, 16, VEIL_SUN_MAX_NODES, &s, &err) == VEIL_ERR_LIMIT,
          "axis limit");
}

static void test_point_linear_exact(void)
{
    veil_grid g = {.dims = {24, 20, 28}, .origin = {-1.0f, 0.5f, 2.0f}, .voxel = 0.1f};
    float* rho = malloc(veil_grid_voxels(&g) * sizeof *rho);
    float rmax = 0;
    for (int k = 0; k < g.dims[2]; ++k)
        for (int j = 0; j < g.dims[1]; ++j)
            for (int i = 0; i < g.dims[0]; ++i) {
                float r = 1.0f + 0.05f * i + 0.03f * j - 0.02f * k;
                rho[((size_t)k * g.dims[1] + j) * g.dims[0] + i] = r;
                rmax = fmaxf(rmax, r);
            }
    for (int L = 0; L < 5; ++L) {
        veil_sun_space s;
        veil_error err = {0};
        if (veil_point_space_make(&g, point_at[L], 0.9f, 1.5f, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err) != VEIL_OK) {
            CHECK(0, "light %d: %s", L, err.msg);
            continue;
        }
        float* D = malloc(veil_sun_space_nodes(&s) * sizeof *D);
        veil_sun_space_cpu(&g, rho, &s, D);
        double light[3], worst = 0;
        for (int q = 0; q < 3; ++q) light[q] = g.origin[q] + ((double)point_at[L][q] + 0.5) * g.voxel;
        const size_t nx = (size_t)s.nodes[0], plane = nx * (size_t)s.nodes[1];
        size_t checked = 0;
        for (int f = 0; f < 6; ++f) {
            const veil_point_face* F = &s.face[f];
            if (!F->nz) continue;
            float fr[6][3];
            veil_sun_space_columns(&s, f, fr);
            for (int k = 0; k < F->nz; ++k)
                for (int j = 0; j < F->nv; ++j)
                    for (int i = 0; i < F->nu; ++i) {
                        double x[3], step2 = 0;
                        for (int q = 0; q < 3; ++q) {
                            double st = fr[3][q] + ((double)i * fr[4][q] + (double)j * fr[5][q]);
                            x[q] = g.origin[q] + (fr[0][q] + i * (double)fr[1][q] + j * (double)fr[2][q] + k * st + 0.5) * g.voxel;
                            step2 += st * st;
                        }
                        double ref = veil_ref_segment_optical_depth(&g, rho, light, x);
                        double d = D[((size_t)F->first + k) * plane + (size_t)j * nx + i];
                        /* the bound of test 2, with this column's step */
                        double bound = (F->nz + 8) * 0x1p-23 * ref + 1e-4 * rmax * sqrt(step2) * g.voxel;
                        worst = fmax(worst, fabs(d - ref) / bound);
                        ++checked;
                    }
        }
        CHECK(worst <= 1.0 && checked > 1000, "light %d: error %.3g of the rounding bound over %zu nodes", L, worst, checked);
        free(D);
    }
    free(rho);
}

int main(void)
{
    test_point_geometry();
    test_point_linear_exact();
    test_plan();
    test_geometry();
    test_linear_exact();
    test_second_order();
    return check_finish();
}
