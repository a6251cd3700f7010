/* veil — light from the environment (scene/environment.h). */
#include "environment.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"
#include "../core/progress.h"
#include "../core/shared.glsl.h"

#define ENV_PI 3.14159265358979323846

struct veil_env_dist {
    int w, h;
    double* row_cdf;  /* h + 1 values, row_cdf[0] = 0, row_cdf[h] = 1 */
    double* cdf;      /* h rows of w + 1 values each: the conditional CDF within the row */
    double* texel_p;  /* w * h: each texel's probability */
};

void veil_env_dist_free(veil_environment* e)
{
    if (!e || !e->dist) return;
    free(e->dist->row_cdf);
    free(e->dist->cdf);
    free(e->dist->texel_p);
    free(e->dist);
    e->dist = NULL;
}

void veil_env_free(veil_environment* e)
{
    if (!e) return;
    free(e->rgb);
    free(e->file);
    veil_env_dist_free(e);
    memset(e, 0, sizeof *e);
}

static double luminance(const double c[3]) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/* Direction in the map's own frame (+Y up) -> world (sign +1: turned by the rotation about +Y, then, with
 * up "z", the frame's (x, y, z) is the world's (x, -z, y)), and back (sign -1). */
static void rotate(const veil_environment* e, const double in[3], double out[3], double sign)
{
    const double a = sign * (double)e->rotation_deg * (ENV_PI / 180.0), c = cos(a), s = sin(a);
    double v[3] = {in[0], in[1], in[2]};
    if (sign < 0.0 && e->up_z) v[0] = in[0], v[1] = in[2], v[2] = -in[1]; /* world -> the +Y-up frame */
    const double x = v[0], z = v[2];
    out[0] = x * c + z * s;
    out[1] = v[1];
    out[2] = -x * s + z * c;
    if (sign > 0.0 && e->up_z) { /* the +Y-up frame -> world */
        const double y = out[1];
        out[1] = -out[2];
        out[2] = y;
    }
}

/* The map's texel seen along map-frame direction m. */
static void texel_of(int w, int h, const double m[3], int* i, int* j)
{
    double n = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    double y = n > 0.0 ? m[1] / n : 1.0;
    double theta = acos(y < -1.0 ? -1.0 : y > 1.0 ? 1.0 : y);
    double phi = atan2(m[2], m[0]) + ENV_PI; /* [0, 2 pi] */
    int ii = (int)floor(phi / (2.0 * ENV_PI) * w), jj = (int)floor(theta / ENV_PI * h);
    *i = ii < 0 ? 0 : ii >= w ? w - 1 : ii;
    *j = jj < 0 ? 0 : jj >= h ? h - 1 : jj;
}

/* Map-frame direction at angles (theta, phi). */
static void direction_at(double cos_theta, double phi, double m[3])
{
    double s = sqrt(fmax(0.0, 1.0 - cos_theta * cos_theta));
    m[0] = -s * cos(phi);
    m[1] = cos_theta;
    m[2] = -s * sin(phi);
}

void veil_env_radiance(const veil_environment* e, const double d[3], double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (!e || !e->present || !e->rgb) return;
    double m[3];
    rotate(e, d, m, -1.0);
    int i, j;
    texel_of(e->width, e->height, m, &i, &j);
    const float* t = e->rgb + 3 * ((size_t)j * (size_t)e->width + (size_t)i);
    for (int k = 0; k < 3; ++k) out[k] = t[k];
}

double veil_env_texel_solid_angle(int w, int h, int j)
{
    return 2.0 * ENV_PI / w * (cos(ENV_PI * j / h) - cos(ENV_PI * (j + 1) / h));
}

void veil_env_integral(const veil_environment* e, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (!e || !e->present || !e->rgb) return;
    for (int j = 0; j < e->height; ++j) {
        double row[3] = {0, 0, 0}, dw = veil_env_texel_solid_angle(e->width, e->height, j);
        for (int i = 0; i < e->width; ++i)
            for (int k = 0; k < 3; ++k) row[k] += e->rgb[3 * ((size_t)j * e->width + i) + k];
        for (int k = 0; k < 3; ++k) out[k] += row[k] * dw;
    }
}

/* ---- median cut ------------------------------------------------------- */

typedef struct {
    int i0, i1, j0, j1; /* texels [i0, i1) x [j0, j1) */
    double energy;      /* luminance x solid angle summed */
} env_region;

typedef enum { PART_ALL, PART_BRIGHT, PART_REST } env_part;

/* The cuts' work, for their progress reports and a cancel (issue 41: an 8K map's cuts take seconds): texels
 * visited, reported (core/progress.h) every ENV_PART_TEXELS of them, out of an estimate of all. */
#define ENV_PART_TEXELS ((size_t)1 << 22)
typedef struct {
    size_t done, since;
    double total;   /* the estimate: the cuts' texel visits (the map's texels x 8 a cut) */
    int cancelled;  /* set once a report finds the cancel flag: the cuts stop, short */
} env_work;

static int env_visit(env_work* w, size_t texels)
{
    if (!w) return 0;
    w->done += texels, w->since += texels;
    if (w->since >= ENV_PART_TEXELS) {
        w->since = 0;
        veil_progress("cutting the environment map", fmin((double)w->done, w->total), w->total);
        w->cancelled = veil_progress_cancelled();
    }
    return w->cancelled;
}

typedef struct {
    int w, h;
    const float* rgb; /* w * h * 3 */
    float one[3];     /* a constant sky's colour (rgb NULL) */
    env_part part;    /* the whole map, or its bright part or its rest above and below `clip` */
    double clip;      /* the split's luminance (veil_environment.clip) */
    double* dw;       /* each row's texel solid angle (h values; NULL: computed at each use) */
    env_work* work;   /* NULL: no reports */
} env_map;

/* m's rows' solid angles, computed once (a cut walks the map's texels several times); NULL when out of
 * memory, which only makes it slower. */
static void rows_made(env_map* m)
{
    m->dw = malloc((size_t)m->h * sizeof *m->dw);
    for (int j = 0; m->dw && j < m->h; ++j) m->dw[j] = veil_env_texel_solid_angle(m->w, m->h, j);
}

static double row_dw(const env_map* m, int j) { return m->dw ? m->dw[j] : veil_env_texel_solid_angle(m->w, m->h, j); }

/* The radiance t split at luminance clip: the rest is t scaled down to luminance clip where it is above it
 * (its colour kept), the bright part what that took away. */
static void split_texel(const float t[3], double clip, env_part part, double out[3])
{
    double c[3] = {t[0], t[1], t[2]}, l = luminance(c);
    double keep = l > clip ? clip / l : 1.0; /* (l > clip > 0 here) */
    for (int k = 0; k < 3; ++k) out[k] = part == PART_ALL ? c[k] : part == PART_REST ? c[k] * keep : c[k] * (1.0 - keep);
}

static void map_texel(const env_map* m, int i, int j, double out[3])
{
    const float* t = m->rgb ? m->rgb + 3 * ((size_t)j * (size_t)m->w + (size_t)i) : m->one;
    split_texel(t, m->clip, m->part, out);
}

static double texel_energy(const env_map* m, int i, int j)
{
    double c[3];
    map_texel(m, i, j, c);
    return luminance(c) * row_dw(m, j);
}

static double region_energy(const env_map* m, int i0, int i1, int j0, int j1)
{
    double s = 0.0;
    for (int j = j0; j < j1; ++j) {
        for (int i = i0; i < i1; ++i) s += texel_energy(m, i, j);
        if (env_visit(m->work, (size_t)(i1 - i0))) break; /* cancelled: the cut is abandoned */
    }
    return s;
}

/* Splits r in two at the texel boundary that halves its energy most evenly, across its longer side in angle;
 * 0 when it is one texel. */
static int split(const env_map* m, const env_region* r, env_region* a, env_region* b)
{
    const int nw = r->i1 - r->i0, nh = r->j1 - r->j0;
    if (nw <= 1 && nh <= 1) return 0;
    double mid = ENV_PI * (0.5 * (r->j0 + r->j1)) / m->h;
    double width = nw * (2.0 * ENV_PI / m->w) * sin(mid), height = nh * (ENV_PI / m->h);
    int across_u = nh <= 1 || (nw > 1 && width >= height);
    int n = across_u ? nw : nh, best = 1;
    double* line = malloc((size_t)n * sizeof *line);
    if (!line) return 0; /* (out of memory: the region stays whole, one light; never wrong, only coarser) */
    for (int k = 0; k < n; ++k)
        line[k] = across_u ? region_energy(m, r->i0 + k, r->i0 + k + 1, r->j0, r->j1)
                           : region_energy(m, r->i0, r->i1, r->j0 + k, r->j0 + k + 1);
    double total = 0.0, prefix = 0.0, best_gap = INFINITY;
    for (int k = 0; k < n; ++k) total += line[k];
    for (int k = 1; k < n; ++k) { /* boundary before line k */
        prefix += line[k - 1];
        double gap = fabs(2.0 * prefix - total);
        if (gap < best_gap) best_gap = gap, best = k;
    }
    double left = 0.0;
    for (int k = 0; k < best; ++k) left += line[k];
    free(line);
    *a = *r, *b = *r;
    if (across_u)
        a->i1 = b->i0 = r->i0 + best;
    else
        a->j1 = b->j0 = r->j0 + best;
    a->energy = left;
    b->energy = fmax(0.0, total - left);
    return 1;
}

static int region_light(const env_map* m, const veil_environment* e, const env_region* r, veil_light* out)
{
    double c[3] = {0, 0, 0}, d[3] = {0, 0, 0};
    for (int j = r->j0; j < r->j1; ++j) {
        if (env_visit(m->work, (size_t)(r->i1 - r->i0))) return 0;
        double dw = row_dw(m, j);
        double ct = cos(ENV_PI * (j + 0.5) / m->h);
        for (int i = r->i0; i < r->i1; ++i) {
            double rgb[3], dir[3];
            map_texel(m, i, j, rgb);
            double wt = luminance(rgb) * dw;
            direction_at(ct, 2.0 * ENV_PI * (i + 0.5) / m->w, dir);
            for (int k = 0; k < 3; ++k) c[k] += rgb[k] * dw, d[k] += wt * dir[k];
        }
    }
    double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(c[0] > 0.0 || c[1] > 0.0 || c[2] > 0.0) || !(n > 0.0)) return 0;
    double world[3];
    for (int k = 0; k < 3; ++k) d[k] /= n;
    rotate(e, d, world, 1.0);
    memset(out, 0, sizeof *out);
    out->type = VEIL_LIGHT_DIRECTIONAL;
    for (int k = 0; k < 3; ++k) {
        out->direction[k] = (float)-world[k]; /* the way the light travels */
        out->color[k] = (float)c[k];
    }
    return 1;
}

/* The part of region r with light: its bounding box of texels with energy (0 when it has none). */
static int lit_box(const env_map* m, const env_region* r, env_region* out)
{
    int i0 = r->i1, i1 = r->i0, j0 = r->j1, j1 = r->j0;
    for (int j = r->j0; j < r->j1; ++j) {
        for (int i = r->i0; i < r->i1; ++i)
            if (texel_energy(m, i, j) > 0.0) {
                i0 = i < i0 ? i : i0, i1 = i + 1 > i1 ? i + 1 : i1;
                j0 = j < j0 ? j : j0, j1 = j + 1 > j1 ? j + 1 : j1;
            }
        if (env_visit(m->work, (size_t)(r->i1 - r->i0))) break;
    }
    if (i0 >= i1) return 0;
    *out = (env_region){i0, i1, j0, j1, r->energy};
    return 1;
}

/* A region's extent in angle: across (at its widest row) and along the meridians, the larger (radians). */
static double region_extent(const env_map* m, const env_region* r)
{
    double t0 = ENV_PI * r->j0 / m->h, t1 = ENV_PI * r->j1 / m->h;
    double widest = t0 <= 0.5 * ENV_PI && t1 >= 0.5 * ENV_PI ? 1.0 : fmax(sin(t0), sin(t1));
    return fmax((r->i1 - r->i0) * (2.0 * ENV_PI / m->w) * widest, t1 - t0);
}

/* The median cut of m's part (the whole map, or its bright part: regions shrunk to their lit texels, and
 * one under VEIL_ENV_POINT_DEG across is not split: it is a sun already). */
static int cut_regions(const veil_environment* e, const env_map* m, int max, veil_light* out)
{
    const int shrink = m->part == PART_BRIGHT;
    env_region regions[VEIL_MAX_LIGHTS];
    if (max > VEIL_MAX_LIGHTS) max = VEIL_MAX_LIGHTS;
    int n = 1;
    regions[0] = (env_region){0, m->w, 0, m->h, region_energy(m, 0, m->w, 0, m->h)};
    if (shrink && !lit_box(m, &regions[0], &regions[0])) return 0;
    const double point = VEIL_ENV_POINT_DEG * (ENV_PI / 180.0);
    while (n < max && !(m->work && m->work->cancelled)) {
        int pick = -1;
        for (int r = 0; r < n; ++r) /* the region carrying the most light that can still be split */
            if ((regions[r].i1 - regions[r].i0 > 1 || regions[r].j1 - regions[r].j0 > 1) &&
                !(shrink && region_extent(m, &regions[r]) <= point) &&
                (pick < 0 || regions[r].energy > regions[pick].energy))
                pick = r;
        if (pick < 0 || !(regions[pick].energy > 0.0)) break;
        env_region a, b;
        if (!split(m, &regions[pick], &a, &b)) break;
        /* (a lit box's edges are lit, so both halves have light; were one dark, the cut stops there) */
        if (shrink && (!lit_box(m, &a, &a) || !lit_box(m, &b, &b))) break;
        regions[pick] = a;
        regions[n++] = b;
    }
    int lights = 0;
    for (int r = 0; r < n; ++r) lights += region_light(m, e, &regions[r], &out[lights]);
    return lights;
}

static int median_cut(const veil_environment* e, env_part part, int max, veil_light* out, env_work* work)
{
    if (!e || !e->present || !e->rgb || max <= 0) return 0;
    env_map m = {e->width, e->height, e->rgb, {0, 0, 0}, part, e->clip, NULL, work};
    if (e->width == 1 && e->height == 1) { /* a constant sky: cut as a 64 x 32 map of itself */
        m.w = 64, m.h = 32, m.rgb = NULL;
        memcpy(m.one, e->rgb, sizeof m.one);
    }
    rows_made(&m);
    const int lights = cut_regions(e, &m, max, out);
    free(m.dw);
    return lights;
}

int veil_env_median_cut(const veil_environment* e, int max, veil_light* out)
{
    return median_cut(e, PART_ALL, max, out, NULL);
}

int veil_env_bright_cut(const veil_environment* e, int max, veil_light* out)
{
    return median_cut(e, PART_BRIGHT, max, out, NULL);
}

double veil_env_mean_luminance(const veil_environment* e)
{
    double total[3];
    veil_env_integral(e, total);
    return luminance(total) / (4.0 * ENV_PI);
}

void veil_env_part_integral(const veil_environment* e, int bright, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (!e || !e->present || !e->rgb) return;
    env_map m = {e->width, e->height, e->rgb, {0, 0, 0}, bright ? PART_BRIGHT : PART_REST, e->clip, NULL, NULL};
    for (int j = 0; j < m.h; ++j) {
        double dw = veil_env_texel_solid_angle(m.w, m.h, j);
        for (int i = 0; i < m.w; ++i) {
            double c[3];
            map_texel(&m, i, j, c);
            for (int k = 0; k < 3; ++k) out[k] += c[k] * dw;
        }
    }
}

void veil_env_frame(const veil_environment* e, float axes[3][3])
{
    for (int a = 0; a < 3; ++a) {
        double in[3] = {a == 0, a == 1, a == 2}, o[3];
        rotate(e, in, o, 1.0);
        for (int k = 0; k < 3; ++k) axes[a][k] = (float)o[k];
    }
}

veil_result veil_env_rest_table(const veil_environment* e, size_t max_texels, veil_env_table* t, veil_error* err)
{
    memset(t, 0, sizeof *t);
    if (!e || !e->present || !e->rgb) return VEIL_OK;
    const int w = e->width, h = e->height;
    int f = 1;
    while ((size_t)((w + f - 1) / f) * (size_t)((h + f - 1) / f) > max_texels) f *= 2;
    const int tw = (w + f - 1) / f, th = (h + f - 1) / f;
    float* en = malloc((size_t)tw * th * 8 * sizeof *en);
    if (!en) return veil_fail(err, VEIL_ERR_OOM, "out of memory for the environment's photon table (%dx%d)", tw, th);
    env_map m = {w, h, e->rgb, {0, 0, 0}, PART_REST, e->clip, NULL, NULL};
    double total = 0.0, bound = 0.0;
    int n = 0;
    for (int bj = 0; bj < th; ++bj)
        for (int bi = 0; bi < tw; ++bi) {
            double c[3] = {0, 0, 0}; /* the block's rgb x solid angle */
            for (int j = bj * f; j < (bj + 1) * f && j < h; ++j) {
                double dw = veil_env_texel_solid_angle(w, h, j);
                for (int i = bi * f; i < (bi + 1) * f && i < w; ++i) {
                    double r[3];
                    map_texel(&m, i, j, r);
                    for (int k = 0; k < 3; ++k) c[k] += r[k] * dw;
                }
            }
            double l = luminance(c);
            if (!(l > 0.0)) continue;
            total += l;
            float* q = en + 8 * (size_t)n++;
            q[0] = (float)(bj * tw + bi);
            q[1] = (float)total; /* divided by the total below */
            q[2] = q[3] = q[7] = 0.0f;
            for (int k = 0; k < 3; ++k) {
                q[4 + k] = (float)(c[k] / l);
                bound = fmax(bound, c[k] / l);
            }
        }
    for (int k = 0; k < n; ++k) en[8 * (size_t)k + 1] = k == n - 1 ? 1.0f : (float)(en[8 * (size_t)k + 1] / total);
    t->w = tw, t->h = th, t->block = f, t->n = n;
    t->entries = en;
    t->total = total;
    t->bound = bound;
    if (n == 0) veil_env_table_free(t);
    return VEIL_OK;
}

void veil_env_table_free(veil_env_table* t)
{
    free(t->entries);
    memset(t, 0, sizeof *t);
}

int veil_env_make_cuts(veil_environment* e, int room, const int* rungs, int n)
{
    e->cut_sets = 0;
    e->room = room < 0 ? 0 : room > VEIL_MAX_LIGHTS ? VEIL_MAX_LIGHTS : room;
    if (!e->present) return 0;
    e->clip = VEIL_ENV_CLIP * veil_env_mean_luminance(e);
    uint64_t key = veil_hash_bytes(VEIL_FNV_OFFSET, &e->width, sizeof e->width);
    key = veil_hash_bytes(key, &e->height, sizeof e->height);
    key = veil_hash_bytes(key, &e->rotation_deg, sizeof e->rotation_deg);
    key = veil_hash_bytes(key, &e->up_z, sizeof e->up_z);
    e->key = veil_hash_words(key, e->rgb, (size_t)e->width * e->height * 3 * sizeof *e->rgb);
    if (e->room == 0) return 0;
    const int one = e->lights;
    if (one > 0) rungs = &one, n = 1;
    env_work work = {.total = 8.0 * 2.0 * n * (double)e->width * (double)e->height};
    for (int r = 0; r < n && e->cut_sets < VEIL_ENV_CUTS && !work.cancelled; ++r) {
        int k = rungs[r] < e->room ? rungs[r] : e->room, seen = 0;
        for (int c = 0; c < e->cut_sets; ++c) seen |= e->cuts[c].k == k;
        if (seen || k < 1) continue;
        veil_env_cut* cut = &e->cuts[e->cut_sets++];
        cut->k = k;
        cut->count = median_cut(e, PART_ALL, k, cut->lights, &work);
        cut->bright_count = median_cut(e, PART_BRIGHT, k, cut->bright, &work);
    }
    if (work.cancelled) e->cut_sets = 0;
    return work.cancelled;
}

const veil_env_cut* veil_env_cut_for(const veil_environment* e, int want)
{
    if (!e || !e->present || e->cut_sets == 0) return NULL;
    int k = e->lights > 0 ? e->lights : want;
    if (k > e->room) k = e->room;
    for (int c = 0; c < e->cut_sets; ++c)
        if (e->cuts[c].k == k) return &e->cuts[c];
    return &e->cuts[0];
}

int veil_env_cut_max(const veil_environment* e)
{
    int m = 0;
    for (int c = 0; e && e->present && c < e->cut_sets; ++c) m = e->cuts[c].count > m ? e->cuts[c].count : m;
    return m;
}

/* ---- importance sampling ---------------------------------------------- */

veil_result veil_env_dist_make(veil_environment* e, veil_error* err)
{
    if (e->dist) return VEIL_OK;
    const int w = e->width, h = e->height;
    veil_env_dist* d = calloc(1, sizeof *d);
    if (d) {
        d->w = w, d->h = h;
        d->row_cdf = malloc(((size_t)h + 1) * sizeof *d->row_cdf);
        d->cdf = malloc((size_t)h * ((size_t)w + 1) * sizeof *d->cdf);
        d->texel_p = malloc((size_t)h * (size_t)w * sizeof *d->texel_p);
    }
    if (!d || !d->row_cdf || !d->cdf || !d->texel_p) {
        if (d) free(d->row_cdf), free(d->cdf), free(d->texel_p);
        free(d);
        return veil_fail(err, VEIL_ERR_OOM, "out of memory for the environment's sampling tables (%dx%d)", w, h);
    }
    env_map m = {w, h, e->rgb, {0, 0, 0}, PART_ALL, 0.0, NULL, NULL};
    double total = 0.0;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) total += texel_energy(&m, i, j);
    const int uniform = !(total > 0.0) || !isfinite(total); /* black: the sphere, uniformly */
    d->row_cdf[0] = 0.0;
    for (int j = 0; j < h; ++j) {
        double* c = d->cdf + (size_t)j * ((size_t)w + 1), row = 0.0, dw = veil_env_texel_solid_angle(w, h, j);
        c[0] = 0.0;
        for (int i = 0; i < w; ++i) {
            double t = uniform ? dw : texel_energy(&m, i, j);
            row += t;
            c[i + 1] = row;
            d->texel_p[(size_t)j * w + i] = t;
        }
        for (int i = 1; i <= w; ++i) c[i] = row > 0.0 ? c[i] / row : (double)i / w;
        d->row_cdf[j + 1] = d->row_cdf[j] + row;
    }
    const double sum = d->row_cdf[h];
    for (int j = 1; j <= h; ++j) d->row_cdf[j] /= sum;
    d->row_cdf[h] = 1.0;
    for (size_t t = 0; t < (size_t)w * h; ++t) d->texel_p[t] /= sum;
    e->dist = d;
    return VEIL_OK;
}

/* The first index k in [0, n) with cdf[k + 1] > u (cdf[0] = 0, cdf[n] = 1), skipping empty ones. */
static int find(const double* cdf, int n, double u)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (cdf[mid + 1] > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    while (lo > 0 && !(cdf[lo + 1] > cdf[lo])) --lo; /* (rounding at the top landed on an empty one) */
    return lo;
}

static double texel_pdf(const veil_env_dist* d, int i, int j)
{
    double p = d->texel_p[(size_t)j * d->w + i];
    return p / veil_env_texel_solid_angle(d->w, d->h, j);
}

double veil_env_sample(const veil_environment* e, double u1, double u2, double u3, double dir[3])
{
    const veil_env_dist* d = e->dist;
    int j = find(d->row_cdf, d->h, u1);
    const double* c = d->cdf + (size_t)j * ((size_t)d->w + 1);
    int i = find(c, d->w, u2);
    double c0 = cos(ENV_PI * j / d->h), c1 = cos(ENV_PI * (j + 1) / d->h);
    double ct = c0 - u3 * (c0 - c1);
    /* where u2 fell within the texel's share of the row: reused as the position across the texel */
    double span = c[i + 1] - c[i], f = span > 0.0 ? (u2 - c[i]) / span : 0.5;
    f = f < 0.0 ? 0.0 : f >= 1.0 ? 0.9999999 : f;
    double m[3];
    direction_at(ct, 2.0 * ENV_PI * (i + f) / d->w, m);
    rotate(e, m, dir, 1.0);
    return texel_pdf(d, i, j);
}

double veil_env_pdf(const veil_environment* e, const double dir[3])
{
    const veil_env_dist* d = e->dist;
    double m[3];
    rotate(e, dir, m, -1.0);
    int i, j;
    texel_of(d->w, d->h, m, &i, &j);
    return texel_pdf(d, i, j);
}
