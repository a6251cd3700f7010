#include "emission_lights.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/shared.glsl.h"
#include "../scene/limits.h"

typedef struct emitter {
    float key;   /* the coordinate a split sorts on */
    float p[3];  /* voxel centre (m) */
    float w;     /* luminance of eps dV */
    float e[3];  /* eps dV, W/sr per channel */
} emitter;

typedef struct cluster {
    size_t begin, end; /* emitters[begin, end) */
    double weight;
} cluster;

/* By the split's coordinate, then the whole position: a total order (voxels
 * differ in position), so the clusters do not depend on the input's order. */
static int by_key(const void* a, const void* b)
{
    const emitter *p = a, *q = b;
    if (p->key != q->key) return (p->key > q->key) - (p->key < q->key);
    for (int i = 0; i < 3; ++i)
        if (p->p[i] != q->p[i]) return (p->p[i] > q->p[i]) - (p->p[i] < q->p[i]);
    return 0;
}

veil_result veil_emission_lights(const veil_grid* g, const float* rgba, int max, veil_light* out, int* n,
                                 veil_error* err)
{
    *n = 0;
    if (!rgba || max < 1) return VEIL_OK;
    size_t voxels = veil_grid_voxels(g), count = 0;
    double dv = (double)g->voxel * g->voxel * g->voxel;
    for (size_t i = 0; i < voxels; ++i)
        count += VEIL_LUM_R * rgba[4 * i] + VEIL_LUM_G * rgba[4 * i + 1] + VEIL_LUM_B * rgba[4 * i + 2] > 0.0;
    if (count == 0) return VEIL_OK;
    float* pts = malloc(count * 6 * sizeof *pts);
    if (!pts) return veil_fail(err, VEIL_ERR_OOM, "out of memory for %zu emitting voxels", count);
    size_t k = 0;
    for (size_t i = 0; i < voxels; ++i) {
        const float* e = rgba + 4 * i;
        if (!(VEIL_LUM_R * e[0] + VEIL_LUM_G * e[1] + VEIL_LUM_B * e[2] > 0.0)) continue;
        int x = (int)(i % (size_t)g->dims[0]), y = (int)(i / (size_t)g->dims[0] % (size_t)g->dims[1]),
            z = (int)(i / ((size_t)g->dims[0] * (size_t)g->dims[1]));
        veil_grid_center(g, x, y, z, pts + 6 * k);
        /* eps dV in double, within VEIL_MAX_LIGHT, its colour kept (a voxel of 1e15 m has dV = 1e45: a
         * float overflows) */
        double p[3] = {e[0] * dv, e[1] * dv, e[2] * dv}, most = fmax(p[0], fmax(p[1], p[2]));
        double keep = most > VEIL_MAX_LIGHT ? VEIL_MAX_LIGHT / most : 1.0;
        for (int c = 0; c < 3; ++c) pts[6 * k + 3 + (size_t)c] = (float)(p[c] * keep);
        ++k;
    }
    veil_result r = veil_emission_lights_points(pts, count, g->voxel, max, out, n, err);
    free(pts);
    return r;
}

veil_result veil_emission_lights_points(const float* pts, size_t count, float voxel, int max, veil_light* out, int* n,
                                        veil_error* err)
{
    *n = 0;
    if (max > VEIL_MAX_LIGHTS) max = VEIL_MAX_LIGHTS;
    if (count == 0 || max < 1) return VEIL_OK;
    emitter* em = malloc(count * sizeof *em);
    if (!em) return veil_fail(err, VEIL_ERR_OOM, "out of memory for %zu emitting voxels", count);
    size_t k = 0;
    for (size_t i = 0; i < count; ++i) {
        /* each voxel's eps dV within VEIL_MAX_LIGHT, its colour kept where it is finite (an infinite
         * channel becomes the bound, the others 0; NaN: no light) */
        const float* q = pts + 6 * i + 3;
        float e[3], most = fmaxf(q[0], fmaxf(q[1], q[2]));
        for (int a = 0; a < 3; ++a)
            e[a] = !(most > (float)VEIL_MAX_LIGHT) ? q[a]
                   : isinf(most)                 ? (isinf(q[a]) ? (float)VEIL_MAX_LIGHT : 0.0f)
                                                 : (float)((double)q[a] * (VEIL_MAX_LIGHT / most));
        double lum = VEIL_LUM_R * e[0] + VEIL_LUM_G * e[1] + VEIL_LUM_B * e[2];
        if (!(lum > 0.0)) continue;
        for (int a = 0; a < 3; ++a) em[k].p[a] = pts[6 * i + (size_t)a], em[k].e[a] = e[a];
        em[k].w = (float)lum;
        ++k;
    }
    count = k;
    if (count == 0) {
        free(em);
        return VEIL_OK;
    }
    cluster cl[VEIL_MAX_LIGHTS];
    cl[0] = (cluster){0, count, 0.0};
    for (size_t i = 0; i < count; ++i) cl[0].weight += em[i].w;
    int m = 1;
    while (m < max) {
        int heavy = -1;
        for (int c = 0; c < m; ++c)
            if (cl[c].end - cl[c].begin > 1 && (heavy < 0 || cl[c].weight > cl[heavy].weight)) heavy = c;
        if (heavy < 0) break;
        cluster* h = &cl[heavy];
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = h->begin; i < h->end; ++i)
            for (int a = 0; a < 3; ++a) lo[a] = fminf(lo[a], em[i].p[a]), hi[a] = fmaxf(hi[a], em[i].p[a]);
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
        for (size_t i = h->begin; i < h->end; ++i) em[i].key = em[i].p[axis];
        qsort(em + h->begin, h->end - h->begin, sizeof *em, by_key);
        /* the weighted median: the first emitter past half the weight (never the first or past the last) */
        double half = 0.5 * h->weight, acc = 0.0;
        size_t cut = h->begin;
        while (cut + 1 < h->end && acc + em[cut].w < half) acc += em[cut++].w;
        if (cut == h->begin) acc += em[cut++].w;
        cl[m] = (cluster){cut, h->end, h->weight - acc};
        h->end = cut, h->weight = acc;
        ++m;
    }
    for (int c = 0; c < m; ++c) {
        double p[3] = {0, 0, 0}, e[3] = {0, 0, 0}, w = 0.0, r2 = 0.0;
        for (size_t i = cl[c].begin; i < cl[c].end; ++i) {
            w += em[i].w;
            for (int a = 0; a < 3; ++a) p[a] += em[i].w * (double)em[i].p[a], e[a] += em[i].e[a];
        }
        if (!(w > 0.0)) continue;
        for (int a = 0; a < 3; ++a) p[a] /= w;
        for (size_t i = cl[c].begin; i < cl[c].end; ++i)
            for (int a = 0; a < 3; ++a) r2 += em[i].w * (em[i].p[a] - p[a]) * (em[i].p[a] - p[a]);
        veil_light* l = &out[(*n)++];
        memset(l, 0, sizeof *l);
        l->type = VEIL_LIGHT_POINT;
        /* an intensity within VEIL_MAX_LIGHT, as every light's (scene/limits.h): scaled down whole, its colour kept */
        double most = fmax(e[0], fmax(e[1], e[2])), keep = most > VEIL_MAX_LIGHT ? VEIL_MAX_LIGHT / most : 1.0;
        for (int a = 0; a < 3; ++a) l->position[a] = (float)p[a], l->color[a] = (float)(e[a] * keep);
        /* the cluster as a uniform ball of the same second moment: a voxel's own spread (a ball of
         * its volume, radius 0.62 h: (3/5) 0.62^2 h^2) adds to its centres' (a union's second moment is
         * the sum); a ball's mean intensity at its centre, eps R, equals a point's I / (4 pi r^2) at
         * r = R / sqrt(3) = sqrt(5/9) RMS (R^2 = (5/3) RMS^2, I = (4/3) pi R^3 eps) */
        double h = voxel, rms2 = r2 / w + 0.6 * pow(3.0 / (4.0 * VEIL_PI), 2.0 / 3.0) * h * h;
        l->radius = (float)sqrt(5.0 / 9.0 * rms2);
    }
    free(em);
    return VEIL_OK;
}
