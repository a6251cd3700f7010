#include "opv_plan.h"

#include <math.h>
#include <stdlib.h>

/* ---- gather sweep ------------------------------------------------------ */

int veil__gather_dist(const veil_grid* g, const veil_index_light* l, int a, int x)
{
    if (l->type == VEIL_LIGHT_DIRECTIONAL) {
        if (l->v[a] > 0.0f) return g->dims[a] - 1 - x;
        if (l->v[a] < 0.0f) return x;
        return 0;
    }
    return abs(x - l->c[a]);
}

/* Distance from integer c to the range [0, n-1]. */
static int range_dist(int c, int n) { return c < 0 ? -c : (c > n - 1 ? c - (n - 1) : 0); }

static int dominant_axis(const float v[3])
{
    int a = 0;
    if (fabsf(v[1]) > fabsf(v[a])) a = 1;
    if (fabsf(v[2]) > fabsf(v[a])) a = 2;
    return a;
}

void veil__gather_plan_make(const veil_grid* g, const veil_index_light* l, veil__gather_plan* p)
{
    p->first = p->last = 0;
    if (l->type == VEIL_LIGHT_DIRECTIONAL) {
        p->solve = dominant_axis(l->v); /* a valid axis: the others may be free */
        for (int a = 0; a < 3; ++a)
            if (l->v[a] != 0.0f) p->last += g->dims[a] - 1;
        return;
    }
    p->solve = 2;
    for (int a = 0; a < 3; ++a) {
        p->first += range_dist(l->c[a], g->dims[a]);
        int far = abs(l->c[a]) > abs(g->dims[a] - 1 - l->c[a]) ? abs(l->c[a]) : abs(g->dims[a] - 1 - l->c[a]);
        p->last += far;
    }
}

int veil__gather_solve(const veil_grid* g, const veil_index_light* l, const veil__gather_plan* p, int m,
                       const int x[3], int out[2])
{
    int s = p->solve, rem = m;
    for (int a = 0; a < 3; ++a)
        if (a != s) rem -= veil__gather_dist(g, l, a, x[a]);
    if (rem < 0) return 0;
    int n = 0, cand[2];
    if (l->type == VEIL_LIGHT_DIRECTIONAL) {
        cand[n++] = l->v[s] > 0.0f ? g->dims[s] - 1 - rem : rem;
    } else {
        cand[n++] = l->c[s] - rem;
        if (rem > 0) cand[n++] = l->c[s] + rem;
    }
    int k = 0;
    for (int i = 0; i < n; ++i)
        if (cand[i] >= 0 && cand[i] < g->dims[s]) out[k++] = cand[i];
    return k;
}

/* ---- semi-Lagrangian shells -------------------------------------------- */

void veil__sl_shell_range(const veil_grid* g, const veil_index_light* l, int* s0, int* s1)
{
    int near = 0, far = 0;
    for (int a = 0; a < 3; ++a) {
        int d = range_dist(l->c[a], g->dims[a]);
        int f = abs(l->c[a]) > abs(g->dims[a] - 1 - l->c[a]) ? abs(l->c[a]) : abs(g->dims[a] - 1 - l->c[a]);
        near = d > near ? d : near;
        far = f > far ? f : far;
    }
    *s0 = near > 2 ? near : 2;
    *s1 = far;
}

/* Clips [lo, lo + n) on axis a to the grid; 0 when empty. */
static int clip(const veil_grid* g, int a, int* lo, int* n)
{
    int hi = *lo + *n - 1;
    if (*lo < 0) *lo = 0;
    if (hi > g->dims[a] - 1) hi = g->dims[a] - 1;
    *n = hi - *lo + 1;
    return *n > 0;
}

int veil__sl_boxes(const veil_grid* g, const veil_index_light* l, int s, int k, veil__box out[VEIL_SL_MAX_BOXES])
{
    int count = 0;
    /* every choice of k axes at distance s (mask), and of their sides */
    for (int mask = 1; mask < 8; ++mask) {
        int bits = (mask & 1) + ((mask >> 1) & 1) + ((mask >> 2) & 1);
        if (bits != k) continue;
        for (int sides = 0; sides < (1 << k); ++sides) {
            veil__box b;
            int ok = 1, bit = 0;
            for (int a = 0; a < 3 && ok; ++a) {
                if (mask & (1 << a)) {
                    b.lo[a] = l->c[a] + ((sides >> bit++) & 1 ? s : -s);
                    b.n[a] = 1;
                } else {
                    b.lo[a] = l->c[a] - s + 1;
                    b.n[a] = 2 * s - 1;
                }
                ok = clip(g, a, &b.lo[a], &b.n[a]);
            }
            if (ok) out[count++] = b;
        }
    }
    return count;
}

int veil__sl_near_box(const veil_grid* g, const veil_index_light* l, veil__box* out)
{
    for (int a = 0; a < 3; ++a) {
        out->lo[a] = l->c[a] - 1;
        out->n[a] = 3;
        if (!clip(g, a, &out->lo[a], &out->n[a])) return 0;
    }
    return 1;
}

int veil__sl_sun_axis(const veil_index_light* l) { return dominant_axis(l->v); }

void veil__sl_sun_slice(const veil_grid* g, const veil_index_light* l, int k, veil__box* out)
{
    int a = dominant_axis(l->v);
    for (int b = 0; b < 3; ++b) {
        out->lo[b] = 0;
        out->n[b] = g->dims[b];
    }
    out->lo[a] = l->v[a] > 0.0f ? g->dims[a] - 1 - k : k;
    out->n[a] = 1;
}
