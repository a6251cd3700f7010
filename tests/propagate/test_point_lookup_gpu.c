/* The march's lookup of a point light's perspective grid
 * (propagate/shaders/lit_medium.glsl, ev_depth_in with `persp`) against
 * its C twin (veil_point_space_depth), which bench/sun_space measures
 * against the exact optical depth.
 *
 * Both read the same nodes (the C twin's prefix sums, uploaded as the
 * renderer's 2D array) at 3000 seeded points of the box, for a light
 * inside the box (six faces) and one outside it, on puffs of smoke. They
 * differ in the GPU's filtering and in rounding:
 *  - bilinear weights between the four columns, which the GL may round to
 *    8 fractional bits: at most 2^-9 of the spread of those four values
 *    (the test takes the spread from the nodes, at the face and plane the
 *    C twin picks);
 *  - the stretch back's density fetches, trilinear: 2^-9 of the largest
 *    density a fetch, over at most `back` metres: 2^-9 rho_max back;
 *  - the face's coordinates in world units (the shader) against index
 *    units (the C twin): a relative 2^-20 of each coordinate moves u, v
 *    and the plane's fraction by that much, D by at most 2^-20 D per
 *    step of the few operations: 1e-5 D in all.
 * Points within 1e-3 of a face's edge (|w|'s two largest components alike)
 * are left out: there the two may pick neighbouring faces, whose columns
 * interpolate the same D differently (an error of the layout, measured by
 * the bench, not a difference of the two codes). A lookup on the wrong
 * face, plane or column is off by far more. */
#include <epoxy/gl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "support/puffs.h"
#include "core/rng.h"
#include "frame/renderer.h"
#include "gpu/gl_util.h"
#include "propagate/lit_medium.h"
#include "propagate/sun_space.h"

#define POINTS 3000

static const char* const SHADER =
    "layout(local_size_x = 64) in;\n"
    "//@include propagate/shaders/lit_medium.glsl\n"
    "layout(std430, binding = 0) readonly buffer veil_pts { vec4 pts[]; };\n"
    "layout(std430, binding = 1) writeonly buffer veil_out { float depth[]; };\n"
    "void main()\n"
    "{\n"
    "    uint i = gl_GlobalInvocationID.x;\n"
    "    if (i >= uint(pts.length())) return;\n"
    "    vec3 x = pts[i].xyz, L = med.sun_light[0].xyz;\n"
    "    float len = length(L - x);\n"
    "    depth[i] = ev_depth_in(0, true, true, 0, x, (L - x) / len, len);\n"
    "}\n";

/* Face, plane and the four columns' spread at index point y, as the C twin picks them. */
static float spread_at(const veil_sun_space* s, const float* D, const float y[3])
{
    float w[3], z, u, v;
    for (int a = 0; a < 3; ++a) w[a] = y[a] - s->origin[a];
    const veil_point_face* F = &s->face[veil_point_face_of(w, &z, &u, &v)];
    float c0 = fminf(fmaxf(floorf((z - F->z0) / s->dz), 0.0f), (float)(F->nz - 1));
    float tu = fminf(fmaxf((u - F->u0) / F->du, 0.0f), (float)(F->nu - 1));
    float tv = fminf(fmaxf((v - F->v0) / F->du, 0.0f), (float)(F->nv - 1));
    int i0 = (int)tu, j0 = (int)tv, i1 = i0 + 1 < F->nu ? i0 + 1 : i0, j1 = j0 + 1 < F->nv ? j0 + 1 : j0;
    const size_t nx = (size_t)s->nodes[0], plane = nx * (size_t)s->nodes[1];
    const float* P = D + ((size_t)F->first + (size_t)c0) * plane;
    float q[4] = {P[j0 * nx + i0], P[j0 * nx + i1], P[j1 * nx + i0], P[j1 * nx + i1]}, lo = q[0], hi = q[0];
    for (int k = 1; k < 4; ++k) lo = fminf(lo, q[k]), hi = fmaxf(hi, q[k]);
    return hi - lo;
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_grid g = {.dims = {40, 34, 30}, .origin = {-1, 0, 1}, .voxel = 0.05f};
    const puff p[3] = {{{8, 9, 7}, 2.0}, {{30, 12, 20}, 1.5}, {{18, 26, 14}, 2.5}};
    float rmax;
    float* rho = puffs_density(&g, p, 3, &rmax);
    GLuint prog = 0, ev = 0, ubo = 0, bufs[2] = {0, 0};
    CHECK(veil_gl_compute_program("test_point_lookup_gpu (lit_medium.glsl)", SHADER, &prog, &err) == VEIL_OK, "%s",
          err.msg);
    CHECK(veil_gl_texture3d(GL_R32F, g.dims, "test EV", &ev, &err) == VEIL_OK, "%s", err.msg);
    glTextureSubImage3D(ev, 0, 0, 0, 0, g.dims[0], g.dims[1], g.dims[2], GL_RED, GL_FLOAT, rho);
    CHECK(veil_gl_buffer(NULL, sizeof(veil_medium_block), GL_DYNAMIC_STORAGE_BIT, "test medium", &ubo, &err) == VEIL_OK,
          "%s", err.msg);
    CHECK(veil_gl_buffer(NULL, POINTS * 16, GL_DYNAMIC_STORAGE_BIT, "test points", &bufs[0], &err) == VEIL_OK, "%s",
          err.msg);
    CHECK(veil_gl_buffer(NULL, POINTS * 4, GL_DYNAMIC_STORAGE_BIT, "test depths", &bufs[1], &err) == VEIL_OK, "%s",
          err.msg);
    const float lights[2][3] = {{20.3f, 16.8f, 15.1f}, {-12.0f, 40.0f, 8.0f}}; /* index coordinates */
    uint64_t rng = 99;
    for (int li = 0; li < 2 && prog; ++li) {
        veil_sun_space s;
        CHECK(veil_point_space_make(&g, lights[li], 0.7f, 2.0f, 1, 2048, VEIL_SUN_MAX_NODES, &s, &err) == VEIL_OK, "%s",
              err.msg);
        size_t n = veil_sun_space_nodes(&s);
        float* D = malloc(n * sizeof *D);
        veil_sun_space_cpu(&g, rho, &s, D);
        GLuint tex = 0;
        CHECK(veil_gl_texture2d_array(GL_R32F, s.nodes, "test grid", &tex, &err) == VEIL_OK, "%s", err.msg);
        glTextureSubImage3D(tex, 0, 0, 0, 0, s.nodes[0], s.nodes[1], s.nodes[2], GL_RED, GL_FLOAT, D);
        /* the medium block as veil_lit_medium_fill makes it for one point light in grid 0 */
        veil_medium_block mb;
        memset(&mb, 0, sizeof mb);
        float lo[3], hi[3];
        veil_grid_medium_box(&g, lo, hi);
        for (int a = 0; a < 3; ++a) {
            mb.box_min[a] = lo[a], mb.box_max[a] = hi[a];
            mb.tex_min[a] = g.origin[a];
            mb.tex_inv_size[a] = 1.0f / ((float)g.dims[a] * g.voxel);
            mb.sun_light[0][a] = g.origin[a] + g.voxel * (s.origin[a] + 0.5f);
            mb.sun_map[0][a] = (float)s.nodes[a];
        }
        mb.shape[1] = g.voxel;
        mb.counts[0] = 1, mb.counts[2] = 1;
        mb.sun_of[0][0] = 1;
        mb.sun_light[0][3] = 1.0f;
        mb.sun_map[0][3] = s.dz;
        const int pieces = veil_point_space_pieces(&s);
        mb.sun_step[0][2] = (float)pieces;
        for (int f = 0; f < 6; ++f) {
            const veil_point_face* F = &s.face[f];
            float* a = mb.sun_face[2 * f];
            float* b = mb.sun_face[2 * f + 1];
            a[0] = F->u0, a[1] = F->v0, a[2] = F->nz ? F->du : 1.0f, a[3] = F->z0;
            b[0] = (float)F->first, b[1] = (float)F->nu, b[2] = (float)F->nv, b[3] = (float)F->nz;
        }
        glNamedBufferSubData(ubo, 0, sizeof mb, &mb);
        float(*pts)[4] = calloc(POINTS, sizeof *pts), *got = malloc(POINTS * sizeof *got);
        for (int i = 0; i < POINTS; ++i)
            for (int a = 0; a < 3; ++a) pts[i][a] = lo[a] + (hi[a] - lo[a]) * (float)veil_rng_double53(&rng);
        glNamedBufferSubData(bufs[0], 0, POINTS * 16, pts);
        glUseProgram(prog);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MEDIUM, ubo);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bufs[0]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bufs[1]);
        glBindTextureUnit(VEIL_TEX_EV, ev);
        glBindTextureUnit(VEIL_TEX_SUN0, tex);
        glDispatchCompute((POINTS + 63) / 64, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(bufs[1], 0, POINTS * 4, got);
        glUseProgram(0);
        CHECK(veil_gl_check("the lookup", &err) == VEIL_OK, "%s", err.msg);
        int bad = 0, checked = 0;
        double worst = 0, dmax = 0;
        for (int i = 0; i < POINTS; ++i) {
            float y[3], w[3], m[3], room = 0;
            for (int a = 0; a < 3; ++a) {
                y[a] = (pts[i][a] - g.origin[a]) / g.voxel - 0.5f;
                w[a] = fabsf(y[a] - s.origin[a]);
                room += (mb.sun_light[0][a] - pts[i][a]) * (mb.sun_light[0][a] - pts[i][a]);
            }
            room = sqrtf(room);
            float to[3], exit_t = room;
            for (int a = 0; a < 3; ++a) {
                to[a] = (mb.sun_light[0][a] - pts[i][a]) / room;
                if (to[a] != 0.0f) {
                    float t = ((to[a] > 0 ? hi[a] : lo[a]) - pts[i][a]) / to[a];
                    exit_t = t < exit_t ? (t > 0 ? t : 0) : exit_t;
                }
            }
            memcpy(m, w, sizeof m); /* the two largest of |w| alike: the edge between two faces */
            float big = fmaxf(m[0], fmaxf(m[1], m[2])), second = m[0] + m[1] + m[2] - big - fminf(m[0], fminf(m[1], m[2]));
            if (big - second < 1e-3f * big) continue;
            double want_d = veil_point_space_depth(&g, rho, &s, D, y, exit_t, pieces);
            double bound = 0x1p-9 * spread_at(&s, D, y) + 0x1p-9 * rmax * s.dz * sqrt(3.0) * g.voxel + 1e-5 * want_d;
            double e = fabs(got[i] - want_d);
            worst = fmax(worst, e / bound);
            dmax = fmax(dmax, want_d);
            bad += !(e <= bound);
            ++checked;
        }
        printf("light %d: %d points, D up to %.3g, |GPU - C| up to %.3g of the bound\n", li, checked, dmax, worst);
        CHECK(bad == 0 && checked > POINTS / 2, "light %d: %d of %d points beyond the bound (worst %.3g of it)", li, bad,
              checked, worst);
        CHECK(dmax > 0.05, "light %d: the puffs cast no shadow (D up to %.3g)", li, dmax);
        free(pts);
        free(got);
        free(D);
        glDeleteTextures(1, &tex);
    }
    glDeleteBuffers(2, bufs);
    glDeleteBuffers(1, &ubo);
    glDeleteTextures(1, &ev);
    glDeleteProgram(prog);
    free(rho);
    veil_gl_destroy(gl);
    return check_finish();
}
