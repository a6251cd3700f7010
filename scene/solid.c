#include "solid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"

/* Voxels kept free on each side of the surface points' box: the thickness
 * behind them and the one-voxel growth, with one to spare. */
#define MARGIN (VEIL_SOLID_MAX_THICKNESS + 2)

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void normalize3(float v[3])
{
    float n = sqrtf(dot3(v, v));
    for (int a = 0; a < 3; ++a) v[a] /= n;
}

/* The ray through image point (sx, sy) in [-1, 1] (x right, y up). */
static void ray_at(const veil_camera_basis* b, float sx, float sy, float dir[3])
{
    for (int a = 0; a < 3; ++a) dir[a] = b->center[a] + sx * b->right[a] + sy * b->up[a];
    normalize3(dir);
}

static size_t index_of(const veil_solid* s, int x, int y, int z)
{
    return (size_t)x + (size_t)s->dims[0] * ((size_t)y + (size_t)s->dims[1] * (size_t)z);
}

int veil_solid_at(const veil_solid* s, const float x[3])
{
    if (!s->voxels) return 0;
    int c[3];
    for (int a = 0; a < 3; ++a) {
        float f = floorf((x[a] - s->origin[a]) / s->voxel);
        if (!(f >= 0.0f && f < (float)s->dims[a])) return 0;
        c[a] = (int)f;
    }
    return s->voxels[index_of(s, c[0], c[1], c[2])] != 0;
}

/* The span of p + t d inside the grid's box, within [0, t_max]; empty: lo > hi. */
static void box_span(const veil_solid* s, const float p[3], const float d[3], float t_max, float* lo, float* hi)
{
    float t0 = 0.0f, t1 = t_max;
    for (int a = 0; a < 3; ++a) {
        float b0 = s->origin[a], b1 = s->origin[a] + (float)s->dims[a] * s->voxel;
        if (d[a] == 0.0f) {
            if (p[a] < b0 || p[a] > b1) t0 = 1.0f, t1 = 0.0f;
            continue;
        }
        float u = (b0 - p[a]) / d[a], v = (b1 - p[a]) / d[a];
        if (u > v) { float w = u; u = v; v = w; }
        t0 = u > t0 ? u : t0;
        t1 = v < t1 ? v : t1;
    }
    *lo = t0, *hi = t1;
}

/* The shaders step the same way (cache_trace.comp's solid_hit): from the
 * span's start, samples every half voxel, the first a quarter voxel in. */
float veil_solid_hit(const veil_solid* s, const float p[3], const float d[3], float t_max)
{
    if (!s->voxels) return t_max;
    float lo, hi;
    box_span(s, p, d, t_max, &lo, &hi);
    const float step = 0.5f * s->voxel;
    for (float t = lo + 0.5f * step; t < hi; t += step) {
        float x[3] = {p[0] + d[0] * t, p[1] + d[1] * t, p[2] + d[2] * t};
        if (veil_solid_at(s, x)) return t;
    }
    return t_max;
}

/* Octahedral map of unit directions to [0, 1]^2 (and back): the square's
 * inner diamond holds z >= 0, its corners z < 0. */
static float sgn(float v) { return v >= 0.0f ? 1.0f : -1.0f; }

static void oct_encode(const float w[3], float uv[2])
{
    float n = fabsf(w[0]) + fabsf(w[1]) + fabsf(w[2]);
    float x = w[0] / n, y = w[1] / n;
    if (w[2] < 0.0f) {
        float ox = (1.0f - fabsf(y)) * sgn(x), oy = (1.0f - fabsf(x)) * sgn(y);
        x = ox, y = oy;
    }
    uv[0] = 0.5f * x + 0.5f, uv[1] = 0.5f * y + 0.5f;
}

static void oct_decode(float u, float v, float w[3])
{
    float x = 2.0f * u - 1.0f, y = 2.0f * v - 1.0f, z = 1.0f - fabsf(x) - fabsf(y);
    if (z < 0.0f) {
        float ox = (1.0f - fabsf(y)) * sgn(x), oy = (1.0f - fabsf(x)) * sgn(y);
        x = ox, y = oy;
    }
    w[0] = x, w[1] = y, w[2] = z;
    normalize3(w);
}

static void basis_of(const float d[3], float u[3], float v[3])
{
    float t[3] = {fabsf(d[0]) < 0.9f ? 1.0f : 0.0f, fabsf(d[0]) < 0.9f ? 0.0f : 1.0f, 0.0f};
    u[0] = d[1] * t[2] - d[2] * t[1], u[1] = d[2] * t[0] - d[0] * t[2], u[2] = d[0] * t[1] - d[1] * t[0];
    normalize3(u);
    v[0] = d[1] * u[2] - d[2] * u[1], v[1] = d[2] * u[0] - d[0] * u[2], v[2] = d[0] * u[1] - d[1] * u[0];
}

/* Light l's map: each texel's path through the grid, the first solid sample. */
static void make_map(veil_solid* s, const veil_light* l, int k)
{
    float* m = s->depth + (size_t)k * VEIL_SOLID_MAP * VEIL_SOLID_MAP;
    const float h = s->voxel;
    if (l->type == VEIL_LIGHT_DIRECTIONAL) {
        float d[3] = {l->direction[0], l->direction[1], l->direction[2]}, u[3], v[3];
        normalize3(d);
        basis_of(d, u, v);
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int c = 0; c < 8; ++c) {
            float x[3];
            for (int a = 0; a < 3; ++a) x[a] = s->origin[a] + ((c >> a) & 1 ? (float)s->dims[a] * h : 0.0f);
            float q[3] = {dot3(x, u), dot3(x, v), dot3(x, d)};
            for (int a = 0; a < 3; ++a) lo[a] = fminf(lo[a], q[a]), hi[a] = fmaxf(hi[a], q[a]);
        }
        /* a texel's margin each side, so that the four taps at the box's edge read inside the map */
        float pad_u = (hi[0] - lo[0]) / (VEIL_SOLID_MAP - 2), pad_v = (hi[1] - lo[1]) / (VEIL_SOLID_MAP - 2);
        lo[0] -= pad_u, hi[0] += pad_u, lo[1] -= pad_v, hi[1] += pad_v;
        float su = 1.0f / (hi[0] - lo[0]), sv = 1.0f / (hi[1] - lo[1]);
        for (int a = 0; a < 3; ++a) s->rows[k][0][a] = u[a] * su, s->rows[k][1][a] = v[a] * sv;
        s->rows[k][0][3] = -lo[0] * su, s->rows[k][1][3] = -lo[1] * sv;
        /* the texel's width and the depth it may span across a surface at up to 60 degrees from the light */
        float texel = fmaxf(hi[0] - lo[0], hi[1] - lo[1]) / VEIL_SOLID_MAP;
        s->bias[k][0] = 2.0f * h + 2.0f * texel, s->bias[k][1] = 0.0f;
        for (int j = 0; j < VEIL_SOLID_MAP; ++j)
            for (int i = 0; i < VEIL_SOLID_MAP; ++i) {
                float cu = lo[0] + ((float)i + 0.5f) * (hi[0] - lo[0]) / VEIL_SOLID_MAP;
                float cv = lo[1] + ((float)j + 0.5f) * (hi[1] - lo[1]) / VEIL_SOLID_MAP;
                float p[3];
                for (int a = 0; a < 3; ++a) p[a] = cu * u[a] + cv * v[a] + lo[2] * d[a];
                float span = hi[2] - lo[2];
                float t = veil_solid_hit(s, p, d, span + 1.0f);
                m[(size_t)j * VEIL_SOLID_MAP + (size_t)i] = t <= span ? lo[2] + t : VEIL_SOLID_FAR;
            }
    } else {
        /* octahedral texels are about 4 pi / MAP^2 sr: sqrt of that, times two, of bias per metre */
        s->bias[k][0] = 2.0f * h, s->bias[k][1] = 2.0f * sqrtf(4.0f * 3.14159265f) / VEIL_SOLID_MAP;
        memset(s->rows[k], 0, sizeof s->rows[k]);
        for (int j = 0; j < VEIL_SOLID_MAP; ++j)
            for (int i = 0; i < VEIL_SOLID_MAP; ++i) {
                float w[3];
                oct_decode(((float)i + 0.5f) / VEIL_SOLID_MAP, ((float)j + 0.5f) / VEIL_SOLID_MAP, w);
                float t = veil_solid_hit(s, l->position, w, VEIL_SOLID_FAR);
                m[(size_t)j * VEIL_SOLID_MAP + (size_t)i] = t < VEIL_SOLID_FAR ? t : VEIL_SOLID_FAR;
            }
    }
}

float veil_solid_visibility(const veil_solid* s, const veil_light* l, int k, const float x[3])
{
    if (!s->voxels || k >= s->maps) return 1.0f;
    float uv[2], dist;
    if (l->type == VEIL_LIGHT_DIRECTIONAL) {
        float d[3] = {l->direction[0], l->direction[1], l->direction[2]};
        normalize3(d);
        uv[0] = dot3(x, s->rows[k][0]) + s->rows[k][0][3];
        uv[1] = dot3(x, s->rows[k][1]) + s->rows[k][1][3];
        if (!(uv[0] >= 0.0f && uv[0] <= 1.0f && uv[1] >= 0.0f && uv[1] <= 1.0f)) return 1.0f;
        dist = dot3(x, d);
    } else {
        float w[3] = {x[0] - l->position[0], x[1] - l->position[1], x[2] - l->position[2]};
        dist = sqrtf(dot3(w, w));
        if (!(dist > 0.0f)) return 1.0f;
        for (int a = 0; a < 3; ++a) w[a] /= dist;
        oct_encode(w, uv);
    }
    float bias = s->bias[k][0] + s->bias[k][1] * dist;
    float fx = uv[0] * VEIL_SOLID_MAP - 0.5f, fy = uv[1] * VEIL_SOLID_MAP - 0.5f;
    float x0 = floorf(fx), y0 = floorf(fy), ax = fx - x0, ay = fy - y0;
    const float* m = s->depth + (size_t)k * VEIL_SOLID_MAP * VEIL_SOLID_MAP;
    float vis = 0.0f;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            int tx = (int)x0 + i, ty = (int)y0 + j;
            tx = tx < 0 ? 0 : (tx > VEIL_SOLID_MAP - 1 ? VEIL_SOLID_MAP - 1 : tx);
            ty = ty < 0 ? 0 : (ty > VEIL_SOLID_MAP - 1 ? VEIL_SOLID_MAP - 1 : ty);
            float wgt = (i ? ax : 1.0f - ax) * (j ? ay : 1.0f - ay);
            if (dist <= m[(size_t)ty * VEIL_SOLID_MAP + (size_t)tx] + bias) vis += wgt;
        }
    return vis;
}

/* One voxel more on every side: a max over 3 along each axis in turn (the 26-neighbourhood). */
static void grow(veil_solid* s, unsigned char* tmp)
{
    for (int axis = 0; axis < 3; ++axis) {
        memcpy(tmp, s->voxels, (size_t)s->dims[0] * s->dims[1] * s->dims[2]);
        for (int z = 0; z < s->dims[2]; ++z)
            for (int y = 0; y < s->dims[1]; ++y)
                for (int x = 0; x < s->dims[0]; ++x) {
                    int c[3] = {x, y, z};
                    if (tmp[index_of(s, x, y, z)]) continue;
                    for (int o = -1; o <= 1; o += 2) {
                        int n[3] = {c[0], c[1], c[2]};
                        n[axis] += o;
                        if (n[axis] < 0 || n[axis] >= s->dims[axis]) continue;
                        if (tmp[index_of(s, n[0], n[1], n[2])]) s->voxels[index_of(s, x, y, z)] = 1;
                    }
                }
    }
}

veil_result veil_solid_build(const veil_camera* cam, int width, int height, const float* distance,
                             const float box_lo[3], const float box_hi[3], const veil_light* lights, int n,
                             veil_solid* s, veil_error* err)
{
    memset(s, 0, sizeof *s);
    veil_camera_basis b;
    veil_result r = veil_camera_make_basis(cam, width, height, &b, err);
    if (r != VEIL_OK) return r;
    /* the surface points' box (those inside the medium's), and the smallest pixel footprint there */
    const float pixel = 2.0f * sqrtf(dot3(b.up, b.up)) / (float)height; /* about: rad a pixel at the centre */
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, foot = INFINITY;
    size_t inside = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            float d = distance[(size_t)y * width + x];
            if (!isfinite(d)) continue;
            float dir[3], p[3];
            veil_camera_ray(&b, width, height, x, y, dir);
            int in = 1;
            for (int a = 0; a < 3; ++a) {
                p[a] = b.pos[a] + dir[a] * d;
                in = in && p[a] >= box_lo[a] && p[a] <= box_hi[a];
            }
            if (!in) continue;
            ++inside;
            for (int a = 0; a < 3; ++a) lo[a] = fminf(lo[a], p[a]), hi[a] = fmaxf(hi[a], p[a]);
            foot = fminf(foot, d * pixel);
        }
    if (!inside) return VEIL_OK;
    float extent = fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
    float h = fmaxf(extent / (float)(VEIL_SOLID_MAX_DIM - 2 * MARGIN), 0.25f * foot);
    h = fmaxf(h, 1e-6f * fmaxf(fabsf(lo[0]), fmaxf(fabsf(lo[1]), fabsf(lo[2])))); /* float can hold it */
    if (!(h > 0.0f)) h = 1e-3f;
    size_t total = 1;
    for (int a = 0; a < 3; ++a) {
        s->origin[a] = lo[a] - MARGIN * h;
        int dim = (int)ceilf((hi[a] - lo[a]) / h) + 2 * MARGIN;
        s->dims[a] = dim < VEIL_SOLID_MAX_DIM ? dim : VEIL_SOLID_MAX_DIM;
        total *= (size_t)s->dims[a];
    }
    s->voxel = h;
    s->voxels = calloc(total, 1);
    unsigned char* tmp = malloc(total);
    if (n > 0) s->depth = malloc((size_t)n * VEIL_SOLID_MAP * VEIL_SOLID_MAP * sizeof *s->depth);
    if (!s->voxels || !tmp || (n > 0 && !s->depth)) {
        free(tmp);
        veil_solid_free(s);
        return veil_fail(err, VEIL_ERR_OOM, "out of memory for the frame's solid (%zu voxels)", total);
    }
    /* each pixel's cone from d to d + thickness, sampled finer than half a voxel across and along */
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            float d = distance[(size_t)y * width + x];
            if (!isfinite(d)) continue;
            float dir[3];
            veil_camera_ray(&b, width, height, x, y, dir);
            float p[3] = {b.pos[0] + dir[0] * d, b.pos[1] + dir[1] * d, b.pos[2] + dir[2] * d};
            if (!(p[0] >= box_lo[0] && p[0] <= box_hi[0] && p[1] >= box_lo[1] && p[1] <= box_hi[1] &&
                  p[2] >= box_lo[2] && p[2] <= box_hi[2]))
                continue;
            float jump = 0.0f;
            const int nb[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
            for (int i = 0; i < 4; ++i) {
                int nx = x + nb[i][0], ny = y + nb[i][1];
                if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
                float dn = distance[(size_t)ny * width + nx];
                if (isfinite(dn)) jump = fmaxf(jump, fabsf(dn - d));
            }
            float thick = fminf(fmaxf(jump, 2.0f * h), VEIL_SOLID_MAX_THICKNESS * h);
            /* 1.5: a pixel is wider off the centre than at it */
            int across = (int)fminf(fmaxf(ceilf(d * pixel * 1.5f / (0.5f * h)), 1.0f), 16.0f);
            int along = (int)ceilf(thick / (0.5f * h)) + 1;
            for (int j = 0; j < across; ++j)
                for (int i = 0; i < across; ++i) {
                    float sx = 2.0f * ((float)x + ((float)i + 0.5f) / (float)across) / (float)width - 1.0f;
                    float sy = 1.0f - 2.0f * ((float)y + ((float)j + 0.5f) / (float)across) / (float)height;
                    float w[3];
                    ray_at(&b, sx, sy, w);
                    for (int k = 0; k < along; ++k) {
                        float t = d + thick * (float)k / (float)(along - 1);
                        float q[3] = {b.pos[0] + w[0] * t, b.pos[1] + w[1] * t, b.pos[2] + w[2] * t};
                        int c[3], ok = 1;
                        for (int a = 0; a < 3; ++a) {
                            float f = floorf((q[a] - s->origin[a]) / h);
                            ok = ok && f >= 0.0f && f < (float)s->dims[a];
                            c[a] = ok ? (int)f : 0;
                        }
                        if (ok) s->voxels[index_of(s, c[0], c[1], c[2])] = 1;
                    }
                }
        }
    grow(s, tmp);
    free(tmp);
    /* a lamp's own surroundings are free: its light starts in the medium */
    for (int l = 0; l < n; ++l) {
        if (lights[l].type == VEIL_LIGHT_DIRECTIONAL) continue;
        float rad = (VEIL_SOLID_LIGHT_CLEAR + 0.87f) * h;
        int c0[3], c1[3];
        for (int a = 0; a < 3; ++a) {
            c0[a] = (int)floorf((lights[l].position[a] - rad - s->origin[a]) / h);
            c1[a] = (int)floorf((lights[l].position[a] + rad - s->origin[a]) / h);
            c0[a] = c0[a] < 0 ? 0 : c0[a];
            c1[a] = c1[a] >= s->dims[a] ? s->dims[a] - 1 : c1[a];
        }
        for (int z = c0[2]; z <= c1[2]; ++z)
            for (int y = c0[1]; y <= c1[1]; ++y)
                for (int x = c0[0]; x <= c1[0]; ++x) {
                    float q[3] = {s->origin[0] + ((float)x + 0.5f) * h, s->origin[1] + ((float)y + 0.5f) * h,
                                  s->origin[2] + ((float)z + 0.5f) * h};
                    float e[3] = {q[0] - lights[l].position[0], q[1] - lights[l].position[1],
                                  q[2] - lights[l].position[2]};
                    if (dot3(e, e) <= rad * rad) s->voxels[index_of(s, x, y, z)] = 0;
                }
    }
    for (size_t i = 0; i < total; ++i) s->solid_count += s->voxels[i];
    s->maps = n < VEIL_MAX_LIGHTS ? n : VEIL_MAX_LIGHTS;
    for (int l = 0; l < s->maps; ++l) make_map(s, &lights[l], l);
    return VEIL_OK;
}

void veil_solid_free(veil_solid* s)
{
    free(s->voxels);
    free(s->depth);
    memset(s, 0, sizeof *s);
}

uint64_t veil_solid_key(uint64_t key, int width, int height, const float* distance)
{
    if (!distance) return key;
    key = veil_hash_bytes(key, "solid", 5);
    return veil_hash_bytes(key, distance, (size_t)width * (size_t)height * sizeof *distance);
}
