#include "sun_space.h"

#include <math.h>
#include <string.h>

static void normalise(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int a = 0; a < 3; ++a) v[a] /= n;
}

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Unit axes: e[2] the travel direction, e[0] and e[1] across it. */
static void frame(const float travel[3], double e[3][3])
{
    for (int a = 0; a < 3; ++a) e[2][a] = travel[a];
    normalise(e[2]);
    int least = 0; /* the coordinate axis least aligned with the light: far from parallel to it */
    for (int a = 1; a < 3; ++a)
        if (fabs(e[2][a]) < fabs(e[2][least])) least = a;
    double ax[3] = {0, 0, 0};
    ax[least] = 1.0;
    cross(e[2], ax, e[0]);
    normalise(e[0]);
    cross(e[2], e[0], e[1]);
}

veil_result veil_sun_space_make(const veil_grid* g, const float travel[3], float across, float along, int panels,
                                int max_axis, size_t max_nodes, veil_sun_space* out, veil_error* err)
{
    memset(out, 0, sizeof *out);
    double len = sqrt((double)travel[0] * travel[0] + (double)travel[1] * travel[1] + (double)travel[2] * travel[2]);
    if (!(len > 0.0) || !isfinite(len) || !(across > 0.0f) || !(along > 0.0f) || !isfinite(across) ||
        !isfinite(along))
        return veil_fail(err, VEIL_ERR_INVALID, "light-space grid: direction (%g, %g, %g), spacing %g, %g voxels",
                         travel[0], travel[1], travel[2], across, along);
    double e[3][3];
    frame(travel, e);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int corner = 0; corner < 8; ++corner) {
        double p[3];
        for (int a = 0; a < 3; ++a) p[a] = (corner >> a) & 1 ? g->dims[a] - 1 : 0;
        for (int r = 0; r < 3; ++r) {
            double d = e[r][0] * p[0] + e[r][1] * p[1] + e[r][2] * p[2];
            lo[r] = d < lo[r] ? d : lo[r];
            hi[r] = d > hi[r] ? d : hi[r];
        }
    }
    const double h[3] = {across, across, along};
    size_t total = 1;
    for (int r = 0; r < 3; ++r) {
        /* nodes 0 .. n-1 span at least [lo, hi]: floor(range / h) + 1 steps */
        double n = floor((hi[r] - lo[r]) / h[r]) + 2.0;
        if (n > max_axis)
            return veil_fail(err, VEIL_ERR_LIMIT, "light-space grid: %.0f nodes on axis %d (most %d)", n, r, max_axis);
        out->nodes[r] = (int)n;
        total *= (size_t)n;
        if (total > max_nodes)
            return veil_fail(err, VEIL_ERR_LIMIT, "light-space grid: more than %zu nodes", max_nodes);
    }
    for (int a = 0; a < 3; ++a) {
        out->origin[a] = (float)(lo[0] * e[0][a] + lo[1] * e[1][a] + lo[2] * e[2][a]);
        for (int r = 0; r < 3; ++r) out->axis[r][a] = (float)(h[r] * e[r][a]);
    }
    int least = (int)ceil(along);
    out->panels = panels > least ? panels : least;
    out->across = across;
    return VEIL_OK;
}

/* One face of a perspective grid (sun_space.h): the window of the box's
 * points with depth z >= eps in the face's frame. (u, v) = offsets / z is a
 * linear-fractional map, so over the convex set box ∩ {z >= eps} its
 * extremes lie at that set's vertices: the box's corners with z >= eps and
 * the points where the box's edges along the axis cross z = eps (edges
 * across the axis keep z constant). Returns 0 when no point of the box has
 * z >= eps. */
static int face_window(const veil_grid* g, const double c[3], int a, int sign, double eps, double* zmin,
                       double* zmax, double win[4])
{
    const int a1 = (a + 1) % 3, a2 = (a + 2) % 3;
    double v[16][3];
    int n = 0;
    for (int corner = 0; corner < 8; ++corner) {
        double p[3];
        for (int q = 0; q < 3; ++q) p[q] = (corner >> q) & 1 ? g->dims[q] - 1 : 0;
        if (sign * (p[a] - c[a]) >= eps) memcpy(v[n++], p, sizeof p);
    }
    double cross_at = c[a] + sign * eps;
    if (cross_at >= 0.0 && cross_at <= g->dims[a] - 1)
        for (int e = 0; e < 4; ++e) {
            v[n][a] = cross_at;
            v[n][a1] = e & 1 ? g->dims[a1] - 1 : 0;
            v[n][a2] = e & 2 ? g->dims[a2] - 1 : 0;
            ++n;
        }
    if (n == 0) return 0;
    *zmin = INFINITY, *zmax = 0.0;
    win[0] = win[2] = 1.0, win[1] = win[3] = -1.0;
    for (int i = 0; i < n; ++i) {
        double z = sign * (v[i][a] - c[a]), u = (v[i][a1] - c[a1]) / z, w = (v[i][a2] - c[a2]) / z;
        *zmin = z < *zmin ? z : *zmin;
        *zmax = z > *zmax ? z : *zmax;
        win[0] = u < win[0] ? u : win[0], win[1] = u > win[1] ? u : win[1];
        win[2] = w < win[2] ? w : win[2], win[3] = w > win[3] ? w : win[3];
    }
    for (int q = 0; q < 4; ++q) win[q] = win[q] < -1.0 ? -1.0 : win[q] > 1.0 ? 1.0 : win[q];
    return win[0] <= win[1] && win[2] <= win[3];
}

veil_result veil_point_space_make(const veil_grid* g, const float light[3], float across, float along, int panels,
                                  int max_axis, size_t max_nodes, veil_sun_space* out, veil_error* err)
{
    memset(out, 0, sizeof *out);
    if (!isfinite(light[0]) || !isfinite(light[1]) || !isfinite(light[2]) || !(across > 0.0f) ||
        !(along > 0.0f) || !isfinite(across) || !isfinite(along))
        return veil_fail(err, VEIL_ERR_INVALID, "light-space grid: light at (%g, %g, %g), spacing %g, %g voxels",
                         light[0], light[1], light[2], across, along);
    const double c[3] = {light[0], light[1], light[2]};
    const double eps = 1e-3; /* voxels: a face's nearest depth that counts (its window saturates to [-1, 1]) */
    int planes = 0, nx = 0, ny = 0, faces = 0;
    for (int f = 0; f < 6; ++f) {
        veil_point_face* F = &out->face[f];
        double zmin, zmax, win[4];
        if (!face_window(g, c, f / 2, f % 2 ? -1 : 1, eps, &zmin, &zmax, win)) continue;
        double du = across / zmax;
        /* plane 0 at the light, or in front of the whole box where a voxel or more of nothing lies before it */
        double z0 = zmin > 1.0 ? zmin : 0.0;
        double nu = floor((win[1] - win[0]) / du) + 2.0, nv = floor((win[3] - win[2]) / du) + 2.0;
        double nz = floor((zmax - z0) / along) + 2.0;
        if (nu > max_axis || nv > max_axis)
            return veil_fail(err, VEIL_ERR_LIMIT, "light-space grid: %.0f x %.0f columns on face %d (most %d)", nu,
                             nv, f, max_axis);
        F->nu = (int)nu, F->nv = (int)nv, F->nz = (int)nz;
        F->first = planes;
        F->u0 = (float)win[0], F->v0 = (float)win[2], F->du = (float)du, F->z0 = (float)z0;
        planes += F->nz;
        nx = F->nu > nx ? F->nu : nx;
        ny = F->nv > ny ? F->nv : ny;
        ++faces;
    }
    if (faces == 0)
        return veil_fail(err, VEIL_ERR_LIMIT, "light-space grid: the light at (%g, %g, %g) sees none of the box",
                         light[0], light[1], light[2]);
    if (planes > max_axis)
        return veil_fail(err, VEIL_ERR_LIMIT, "light-space grid: %d planes (most %d)", planes, max_axis);
    if ((double)nx * ny * planes > (double)max_nodes)
        return veil_fail(err, VEIL_ERR_LIMIT, "light-space grid: more than %zu nodes", max_nodes);
    out->nodes[0] = nx, out->nodes[1] = ny, out->nodes[2] = planes;
    for (int a = 0; a < 3; ++a) out->origin[a] = light[a];
    out->panels = panels > 1 ? panels : 1;
    out->across = across;
    out->perspective = 1;
    out->dz = along;
    return VEIL_OK;
}

void veil_sun_space_columns(const veil_sun_space* s, int f, float frame[6][3])
{
    memset(frame, 0, 6 * sizeof frame[0]);
    if (!s->perspective) {
        for (int a = 0; a < 3; ++a) {
            frame[0][a] = s->origin[a];
            frame[1][a] = s->axis[0][a];
            frame[2][a] = s->axis[1][a];
            frame[3][a] = s->axis[2][a];
        }
        return;
    }
    const veil_point_face* F = &s->face[f];
    const int a = f / 2, a1 = (a + 1) % 3, a2 = (a + 2) % 3;
    double d[3]; /* the direction of column (0, 0) per unit depth */
    d[a] = f % 2 ? -1.0 : 1.0;
    d[a1] = F->u0;
    d[a2] = F->v0;
    for (int q = 0; q < 3; ++q) {
        frame[0][q] = (float)(s->origin[q] + (double)F->z0 * d[q]);
        frame[3][q] = (float)((double)s->dz * d[q]);
    }
    frame[1][a1] = (float)((double)F->z0 * F->du);
    frame[2][a2] = (float)((double)F->z0 * F->du);
    frame[4][a1] = (float)((double)s->dz * F->du);
    frame[5][a2] = (float)((double)s->dz * F->du);
}

size_t veil_sun_space_nodes(const veil_sun_space* s)
{
    return (size_t)s->nodes[0] * (size_t)s->nodes[1] * (size_t)s->nodes[2];
}

void veil_sun_space_to_texture(const veil_grid* g, const veil_sun_space* s, float m[3][4])
{
    /* index u = (x - grid origin) / voxel - 1/2; node coordinate r = (u - origin) . axis_r / |axis_r|^2;
     * texture coordinate (r + 1/2) / nodes_r */
    for (int r = 0; r < 3; ++r) {
        double len2 = 0.0;
        for (int a = 0; a < 3; ++a) len2 += (double)s->axis[r][a] * s->axis[r][a];
        double k = 1.0 / (len2 * s->nodes[r]), c = 0.0;
        for (int a = 0; a < 3; ++a) {
            m[r][a] = (float)(k * s->axis[r][a] / g->voxel);
            c -= k * s->axis[r][a] * ((double)g->origin[a] / g->voxel + 0.5 + s->origin[a]);
        }
        m[r][3] = (float)(c + 0.5 / s->nodes[r]);
    }
}

/* Trilinear density at index coordinate p, clamped into the box (as a
 * clamp-to-edge fetch of a texture is). */
static float density_at(const veil_grid* g, const float* rho, const float p[3])
{
    int i0[3], i1[3];
    float f[3];
    for (int a = 0; a < 3; ++a) {
        float q = fminf(fmaxf(p[a], 0.0f), (float)(g->dims[a] - 1));
        float fl = floorf(q);
        i0[a] = (int)fl;
        i1[a] = i0[a] + 1 < g->dims[a] ? i0[a] + 1 : i0[a];
        f[a] = q - fl;
    }
    const size_t nx = (size_t)g->dims[0], nxy = nx * (size_t)g->dims[1];
#define V(i, j, k) rho[(size_t)(k) * nxy + (size_t)(j) * nx + (size_t)(i)]
    float c00 = V(i0[0], i0[1], i0[2]) + f[0] * (V(i1[0], i0[1], i0[2]) - V(i0[0], i0[1], i0[2]));
    float c10 = V(i0[0], i1[1], i0[2]) + f[0] * (V(i1[0], i1[1], i0[2]) - V(i0[0], i1[1], i0[2]));
    float c01 = V(i0[0], i0[1], i1[2]) + f[0] * (V(i1[0], i0[1], i1[2]) - V(i0[0], i0[1], i1[2]));
    float c11 = V(i0[0], i1[1], i1[2]) + f[0] * (V(i1[0], i1[1], i1[2]) - V(i0[0], i1[1], i1[2]));
#undef V
    float c0 = c00 + f[1] * (c10 - c00), c1 = c01 + f[1] * (c11 - c01);
    return c0 + f[2] * (c1 - c0);
}

/* One column: node 0 at p0, node k at p0 + k ax, n nodes; D written to
 * out[k * stride]. step: metres per node step. As sun_prefix.comp. */
static void column(const veil_grid* g, const float* rho, const float p0[3], const float ax[3], int nodes, int panels,
                   float step, float* out, size_t stride)
{
    /* the column's span in the box, in node steps: [enter, leave] */
    float enter = 0.0f, leave = (float)(nodes - 1);
    for (int a = 0; a < 3; ++a) {
        float hi = (float)(g->dims[a] - 1);
        if (ax[a] == 0.0f) {
            if (p0[a] < 0.0f || p0[a] > hi) leave = -1.0f;
            continue;
        }
        float t0 = (0.0f - p0[a]) / ax[a], t1 = (hi - p0[a]) / ax[a];
        enter = fmaxf(enter, fminf(t0, t1));
        leave = fminf(leave, fmaxf(t0, t1));
    }
    float D = 0.0f, s_last = -1.0f, f_last = 0.0f;
    out[0] = 0.0f;
    for (int k = 1; k < nodes; ++k) {
        float lo = fmaxf((float)(k - 1), enter), hi = fminf((float)k, leave);
        if (lo < hi) {
            float w = (hi - lo) / (float)panels, sum = 0.0f;
            for (int q = 0; q < panels; ++q) {
                float a = lo + (float)q * w, b = q + 1 == panels ? hi : lo + (float)(q + 1) * w;
                float m = 0.5f * (a + b), pa[3], pm[3], pb[3];
                for (int c = 0; c < 3; ++c) {
                    pa[c] = p0[c] + a * ax[c];
                    pm[c] = p0[c] + m * ax[c];
                    pb[c] = p0[c] + b * ax[c];
                }
                float fa = a == s_last ? f_last : density_at(g, rho, pa);
                float fm = density_at(g, rho, pm), fb = density_at(g, rho, pb);
                sum += (b - a) * (fa + 4.0f * fm + fb);
                s_last = b;
                f_last = fb;
            }
            D += sum * (step / 6.0f);
        }
        out[(size_t)k * stride] = D;
    }
}

void veil_sun_space_cpu(const veil_grid* g, const float* rho, const veil_sun_space* s, float* out)
{
    const size_t plane = (size_t)s->nodes[0] * (size_t)s->nodes[1];
    if (!s->perspective) {
        const float* ax = s->axis[2];
        float step = sqrtf(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]) * g->voxel; /* m per node step */
        for (int j = 0; j < s->nodes[1]; ++j)
            for (int i = 0; i < s->nodes[0]; ++i) {
                float p0[3];
                for (int a = 0; a < 3; ++a) p0[a] = s->origin[a] + (float)i * s->axis[0][a] + (float)j * s->axis[1][a];
                column(g, rho, p0, ax, s->nodes[2], s->panels, step, out + (size_t)j * (size_t)s->nodes[0] + (size_t)i,
                       plane);
            }
        return;
    }
    for (int f = 0; f < 6; ++f) {
        const veil_point_face* F = &s->face[f];
        if (F->nz == 0) continue;
        float fr[6][3];
        veil_sun_space_columns(s, f, fr);
        for (int j = 0; j < s->nodes[1]; ++j)
            for (int i = 0; i < s->nodes[0]; ++i) {
                float* o = out + (size_t)F->first * plane + (size_t)j * (size_t)s->nodes[0] + (size_t)i;
                if (i >= F->nu || j >= F->nv) { /* outside the face's window: 0, as the shader writes */
                    for (int k = 0; k < F->nz; ++k) o[(size_t)k * plane] = 0.0f;
                    continue;
                }
                float p0[3], ax[3];
                for (int a = 0; a < 3; ++a) {
                    p0[a] = fr[0][a] + (float)i * fr[1][a] + (float)j * fr[2][a];
                    ax[a] = fr[3][a] + ((float)i * fr[4][a] + (float)j * fr[5][a]); /* as the shader adds */
                }
                float len = sqrtf(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
                int least = (int)ceilf(len), panels = s->panels > least ? s->panels : least;
                column(g, rho, p0, ax, F->nz, panels, len * g->voxel, o, plane);
            }
    }
}

double veil_point_space_work(const veil_grid* g, const veil_sun_space* s)
{
    double work = 0.0;
    for (int f = 0; f < 6; ++f) {
        const veil_point_face* F = &s->face[f];
        if (F->nz == 0) continue;
        float fr[6][3];
        veil_sun_space_columns(s, f, fr);
        for (int j = 0; j < F->nv; ++j)
            for (int i = 0; i < F->nu; ++i) {
                double p0[3], ax[3], enter = 0.0, leave = F->nz - 1, len = 0.0;
                for (int a = 0; a < 3; ++a) {
                    p0[a] = fr[0][a] + i * (double)fr[1][a] + j * (double)fr[2][a];
                    ax[a] = fr[3][a] + (i * (double)fr[4][a] + j * (double)fr[5][a]);
                    len += ax[a] * ax[a];
                }
                for (int a = 0; a < 3; ++a) {
                    double hi = g->dims[a] - 1;
                    if (ax[a] == 0.0) {
                        if (p0[a] < 0.0 || p0[a] > hi) leave = -1.0;
                        continue;
                    }
                    double t0 = -p0[a] / ax[a], t1 = (hi - p0[a]) / ax[a];
                    enter = fmax(enter, fmin(t0, t1));
                    leave = fmin(leave, fmax(t0, t1));
                }
                if (leave > enter) work += (leave - enter) * sqrt(len);
            }
    }
    return work;
}

float veil_point_space_depth(const veil_grid* g, const float* rho, const veil_sun_space* s, const float* D,
                             const float y[3], float room, int pieces)
{
    float w[3], z, u, v;
    for (int a = 0; a < 3; ++a) w[a] = y[a] - s->origin[a];
    int f = veil_point_face_of(w, &z, &u, &v);
    const veil_point_face* F = &s->face[f];
    if (F->nz == 0) return 0.0f;
    float c0 = fmaxf(floorf((z - F->z0) / s->dz), 0.0f);
    c0 = fminf(c0, (float)(F->nz - 1));
    float zp = F->z0 + c0 * s->dz;
    float dist = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    float back = fmaxf(z - zp, 0.0f) / fmaxf(z, 1e-6f) * dist * g->voxel; /* m to the plane, towards the light */
    back = fminf(back, room);
    /* bilinear between the four columns, as a texture's linear filter (clamped to the face's window) */
    float tu = fminf(fmaxf((u - F->u0) / F->du, 0.0f), (float)(F->nu - 1));
    float tv = fminf(fmaxf((v - F->v0) / F->du, 0.0f), (float)(F->nv - 1));
    int i0 = (int)floorf(tu), j0 = (int)floorf(tv);
    int i1 = i0 + 1 < F->nu ? i0 + 1 : i0, j1 = j0 + 1 < F->nv ? j0 + 1 : j0;
    float fu = tu - (float)i0, fv = tv - (float)j0;
    const size_t nx = (size_t)s->nodes[0], plane = nx * (size_t)s->nodes[1];
    const float* P = D + ((size_t)F->first + (size_t)c0) * plane;
    float d0 = P[(size_t)j0 * nx + (size_t)i0] + fu * (P[(size_t)j0 * nx + (size_t)i1] - P[(size_t)j0 * nx + (size_t)i0]);
    float d1 = P[(size_t)j1 * nx + (size_t)i0] + fu * (P[(size_t)j1 * nx + (size_t)i1] - P[(size_t)j1 * nx + (size_t)i0]);
    float out = d0 + fv * (d1 - d0);
    if (back > 0.0f && dist > 0.0f) {
        float piece = back / (float)pieces, to[3];
        for (int a = 0; a < 3; ++a) to[a] = -w[a] / dist;
        for (int i = 0; i < pieces; ++i) {
            float t = piece * ((float)i + 0.5f) / g->voxel, p[3];
            for (int a = 0; a < 3; ++a) p[a] = y[a] + to[a] * t;
            out += density_at(g, rho, p) * piece;
        }
    }
    return out;
}

int veil_point_space_pieces(const veil_sun_space* s)
{
    /* the stretch back is at most dz along the axis, dz |d| along the ray, |d| <= sqrt(1 + u^2 + v^2) */
    float most = 0.0f;
    for (int f = 0; f < 6; ++f) {
        const veil_point_face* F = &s->face[f];
        if (F->nz == 0) continue;
        float um = fmaxf(fabsf(F->u0), fabsf(F->u0 + (float)(F->nu - 1) * F->du));
        float vm = fmaxf(fabsf(F->v0), fabsf(F->v0 + (float)(F->nv - 1) * F->du));
        float d = sqrtf(1.0f + fminf(um * um, 1.0f) + fminf(vm * vm, 1.0f));
        most = fmaxf(most, d);
    }
    int n = (int)ceilf(s->dz * most / VEIL_POINT_PIECE);
    return n > 1 ? n : 1;
}
