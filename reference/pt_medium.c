/* veil — the path tracer's medium: construction, majorants, delta and
 * ratio tracking (see reference/pathtracer.h for the estimators).
 *
 * Two kinds of medium are superposed along a ray, and each is tracked as
 * its own Poisson process of tentative collisions; the first tentative
 * collision of the superposition is the earliest of theirs (decomposition
 * tracking), and after a null collision each process just goes on
 * (memorylessness: a pending candidate beyond the null collision is still
 * a valid sample of that process).
 *  - The volume: rate sigma_max * (block maximum of the voxel values), a
 *    majorant piecewise constant along the ray, walked block by block.
 *  - Each fog: rate sigma_max * rho_fog(x) exactly. Along a line the fog is
 *    rho_a exp(-m s), so the collision distance is sampled by inverting its
 *    optical depth in closed form, s = -log1p(-E m / (sigma_max rho_a)) / m
 *    (E a unit exponential; no collision when the argument reaches 1). A
 *    fog collision's event probabilities sigma_x / (sigma_max rho) do not
 *    depend on the density, so extreme densities never enter them.
 */
#include "pt_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../volume/scene_volume.h"
#include "closed_forms.h"
#include "optical_depth.h"

/* ---- geometry ------------------------------------------------------------ */

int veil__pt_box_clip(const double lo[3], const double hi[3], const double o[3], const double d[3], double t0,
                      double t1, double* a, double* b)
{
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0) {
            if (!(o[k] >= lo[k] && o[k] <= hi[k])) return 0;
            continue;
        }
        double inv = 1.0 / d[k];
        double ta = (lo[k] - o[k]) * inv, tb = (hi[k] - o[k]) * inv;
        if (ta > tb) {
            double s = ta;
            ta = tb;
            tb = s;
        }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
    }
    if (!(t0 < t1)) return 0; /* also NaN */
    *a = t0;
    *b = t1;
    return 1;
}

/* ---- construction ---------------------------------------------------------- */

/* Block maxima: block (bi, bj, bk) holds the trilinear cells
 * [b*B, (b+1)*B) per axis, whose corners are the voxels b*B .. (b+1)*B; one
 * more voxel on each side is included, so that a position rounded into the
 * neighbouring block still sees a true majorant. */
static int build_majorants(veil_pt_medium* m)
{
    const int B = VEIL_PT_MAJORANT_BLOCK;
    const int* n = m->grid.dims;
    size_t count = 1;
    for (int a = 0; a < 3; ++a) {
        m->nb[a] = (n[a] - 1 + B - 1) / B;
        count *= (size_t)m->nb[a];
    }
    m->major = malloc(count * sizeof(float));
    if (!m->major) return 0;
    for (int bk = 0; bk < m->nb[2]; ++bk)
        for (int bj = 0; bj < m->nb[1]; ++bj)
            for (int bi = 0; bi < m->nb[0]; ++bi) {
                int b[3] = {bi, bj, bk}, lo[3], hi[3];
                for (int a = 0; a < 3; ++a) {
                    lo[a] = b[a] * B - 1 < 0 ? 0 : b[a] * B - 1;
                    hi[a] = (b[a] + 1) * B + 1 > n[a] - 1 ? n[a] - 1 : (b[a] + 1) * B + 1;
                }
                float mx = 0.0f;
                for (int k = lo[2]; k <= hi[2]; ++k)
                    for (int j = lo[1]; j <= hi[1]; ++j)
                        for (int i = lo[0]; i <= hi[0]; ++i) {
                            float v = m->rho[((size_t)k * (size_t)n[1] + (size_t)j) * (size_t)n[0] + (size_t)i];
                            if (v > mx) mx = v;
                        }
                m->major[((size_t)bk * (size_t)m->nb[1] + (size_t)bj) * (size_t)m->nb[0] + (size_t)bi] = mx;
            }
    return 1;
}

static void set_coefficients(veil_pt_medium* m, const veil_scene* s)
{
    m->sigma_max = 0.0;
    for (int c = 0; c < 3; ++c) {
        m->sigma_a[c] = s->medium.sigma_a[c];
        m->sigma_s[c] = s->medium.sigma_s[c];
        m->sigma_t[c] = m->sigma_a[c] + m->sigma_s[c];
        if (m->sigma_t[c] > m->sigma_max) m->sigma_max = m->sigma_t[c];
    }
    m->fog_count = 0;
    for (size_t i = 0; i < s->medium.source_count && m->fog_count < VEIL_MAX_FOGS; ++i) {
        const veil_source* src = &s->medium.sources[i];
        if (src->type != VEIL_SOURCE_EXPONENTIAL || !(src->fog.density > 0.0f)) continue;
        pt_fog* f = &m->fog[m->fog_count++];
        f->rho0 = src->fog.density;
        f->falloff = src->fog.falloff;
        double len = 0.0;
        for (int a = 0; a < 3; ++a) len += (double)src->fog.direction[a] * src->fog.direction[a];
        len = sqrt(len);
        for (int a = 0; a < 3; ++a) {
            f->n[a] = len > 0.0 ? src->fog.direction[a] / len : 0.0;
            f->o[a] = src->fog.origin[a];
            f->lo[a] = src->fog.bounds[0][a];
            f->hi[a] = src->fog.bounds[1][a];
        }
    }
}

veil_result veil_pt_medium_from_density(const veil_scene* s, const veil_grid* g, const float* density,
                                        veil_pt_medium** out, veil_error* err)
{
    *out = NULL;
    veil_pt_medium* m = calloc(1, sizeof *m);
    if (!m) return veil_fail(err, VEIL_ERR_OOM, "out of memory for the reference medium");
    set_coefficients(m, s);
    if (g && density) {
        m->grid = *g;
        m->has_grid = g->dims[0] >= 2 && g->dims[1] >= 2 && g->dims[2] >= 2 && g->voxel > 0.0f;
        size_t n = veil_grid_voxels(g);
        m->rho = m->has_grid ? malloc(n * sizeof(float)) : NULL;
        if (m->has_grid && !m->rho) {
            free(m);
            return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-voxel reference volume", n);
        }
        if (m->has_grid) {
            for (size_t i = 0; i < n; ++i) { /* negative or NaN density is no medium */
                float v = density[i];
                m->rho[i] = v > 0.0f && v <= FLT_MAX ? v : (v > FLT_MAX ? FLT_MAX : 0.0f);
            }
            for (int a = 0; a < 3; ++a) {
                m->box_lo[a] = (double)g->origin[a] + 0.5 * (double)g->voxel;
                m->box_hi[a] = (double)g->origin[a] + ((double)g->dims[a] - 0.5) * (double)g->voxel;
            }
            if (!build_majorants(m)) {
                veil_pt_medium_free(m);
                return veil_fail(err, VEIL_ERR_OOM, "out of memory for the majorant blocks");
            }
        }
    }
    *out = m;
    return VEIL_OK;
}

veil_result veil_pt_medium_from_scene(const veil_scene* s, veil_pt_medium** out, veil_error* err)
{
    *out = NULL;
    veil_scene_volume v;
    veil_result r = veil_scene_volume_open(s, &v, err);
    if (r != VEIL_OK) return r;
    float *density = NULL, *emission = NULL;
    if (v.has_volume) r = veil_scene_volume_density(&v, &density, err);
    if (r == VEIL_OK) r = veil_scene_volume_emission(&v, &emission, err);
    if (r == VEIL_OK) r = veil_pt_medium_from_density(s, v.has_volume ? &v.grid : NULL, density, out, err);
    if (r == VEIL_OK && emission && (*out)->has_grid) {
        size_t n = veil_grid_voxels(&v.grid);
        for (int c = 0; c < 3 && r == VEIL_OK; ++c) {
            float* plane = malloc(n * sizeof *plane);
            if (!plane) {
                r = veil_fail(err, VEIL_ERR_OOM, "out of memory for the emission");
                break;
            }
            for (size_t k = 0; k < n; ++k) plane[k] = emission[4 * k + (size_t)c];
            (*out)->emission[c] = plane;
        }
        if (r != VEIL_OK) {
            veil_pt_medium_free(*out);
            *out = NULL;
        }
    }
    free(density);
    free(emission);
    veil_scene_volume_close(&v);
    return r;
}

void veil_pt_medium_free(veil_pt_medium* m)
{
    if (!m) return;
    for (int c = 0; c < 3; ++c) free(m->emission[c]);
    free(m->rho);
    free(m->major);
    free(m);
}

const veil_grid* veil_pt_medium_grid(const veil_pt_medium* m) { return m->has_grid ? &m->grid : NULL; }

/* ---- densities --------------------------------------------------------------- */

/* log of fog f's density at x (-inf for none). */
static double fog_log_density(const pt_fog* f, const double x[3])
{
    double k = 0.0;
    for (int a = 0; a < 3; ++a) k += (x[a] - f->o[a]) * f->n[a];
    return log(f->rho0) - f->falloff * k;
}

double veil__pt_density(const veil_pt_medium* m, const double x[3])
{
    double rho = m->has_grid ? veil_ev_sample(&m->grid, m->rho, x) : 0.0;
    for (int i = 0; i < m->fog_count; ++i) {
        const pt_fog* f = &m->fog[i];
        int inside = 1;
        for (int k = 0; k < 3; ++k) inside &= x[k] >= f->lo[k] && x[k] <= f->hi[k];
        if (inside) rho += exp(fog_log_density(f, x));
    }
    return rho;
}

int veil__pt_medium_span(const veil_pt_medium* m, const double o[3], const double d[3], double* a, double* b)
{
    double lo = INFINITY, hi = -INFINITY, ta, tb;
    if (!(m->sigma_max > 0.0)) return 0;
    if (m->has_grid && veil__pt_box_clip(m->box_lo, m->box_hi, o, d, 0.0, INFINITY, &ta, &tb)) {
        lo = ta;
        hi = tb;
    }
    for (int i = 0; i < m->fog_count; ++i)
        if (veil__pt_box_clip(m->fog[i].lo, m->fog[i].hi, o, d, 0.0, INFINITY, &ta, &tb)) {
            lo = fmin(lo, ta);
            hi = fmax(hi, tb);
        }
    if (!(lo < hi)) return 0;
    *a = lo;
    *b = hi;
    return 1;
}

/* ---- the volume's majorant walk ----------------------------------------------- */

typedef struct dda {
    int blk[3], step[3];
    double tnext[3], tdelta[3];
    double t, t_end; /* the current block starts at t */
    int done;
} dda;

static int dda_init(const veil_pt_medium* m, const double o[3], const double d[3], double t0, double t1, dda* w)
{
    double a, b;
    w->done = 1;
    if (!m->has_grid || !veil__pt_box_clip(m->box_lo, m->box_hi, o, d, t0, t1, &a, &b)) return 0;
    const double h = m->grid.voxel, B = VEIL_PT_MAJORANT_BLOCK;
    for (int k = 0; k < 3; ++k) {
        double u = (o[k] + a * d[k] - m->box_lo[k]) / (h * B); /* block coordinate of the entry */
        int blk = (int)floor(u);
        if (d[k] < 0.0 && (double)blk == u) --blk;
        blk = blk < 0 ? 0 : (blk >= m->nb[k] ? m->nb[k] - 1 : blk);
        w->blk[k] = blk;
        if (d[k] == 0.0) {
            w->step[k] = 0;
            w->tnext[k] = w->tdelta[k] = INFINITY;
        } else {
            w->step[k] = d[k] > 0.0 ? 1 : -1;
            double edge = m->box_lo[k] + (double)(blk + (d[k] > 0.0)) * h * B;
            w->tnext[k] = (edge - o[k]) / d[k];
            w->tdelta[k] = h * B / fabs(d[k]);
        }
    }
    w->t = a;
    w->t_end = b;
    w->done = 0;
    return 1;
}

/* The current block's [t, end) and majorant (density units). */
static double dda_block(const veil_pt_medium* m, const dda* w, double* end)
{
    double e = fmin(fmin(w->tnext[0], w->tnext[1]), fmin(w->tnext[2], w->t_end));
    *end = e;
    return m->major[((size_t)w->blk[2] * (size_t)m->nb[1] + (size_t)w->blk[1]) * (size_t)m->nb[0] + (size_t)w->blk[0]];
}

static void dda_advance(const veil_pt_medium* m, dda* w)
{
    int k = w->tnext[0] <= w->tnext[1] ? (w->tnext[0] <= w->tnext[2] ? 0 : 2) : (w->tnext[1] <= w->tnext[2] ? 1 : 2);
    double end = fmin(w->tnext[k], w->t_end);
    if (end >= w->t_end) {
        w->done = 1;
        return;
    }
    w->t = end;
    w->blk[k] += w->step[k];
    w->tnext[k] += w->tdelta[k];
    if (w->blk[k] < 0 || w->blk[k] >= m->nb[k]) w->done = 1;
}

/* The volume's next tentative collision at or after w->t: its distance
 * (INFINITY when none) and the majorant there (rate = sigma_max * *major). */
static double grid_candidate(const veil_pt_medium* m, dda* w, pt_rng* rng, double* major)
{
    while (!w->done) {
        double end, mj = dda_block(m, w, &end);
        double rate = m->sigma_max * mj;
        if (rate > 0.0) {
            double t = w->t - log1p(-pt_uniform(rng)) / rate;
            if (t < end) {
                w->t = t;
                *major = mj;
                return t;
            }
        }
        dda_advance(m, w);
    }
    return INFINITY;
}

/* Fog f's next tentative collision beyond t0 along o + t d (rate
 * sigma_max * rho_fog): INFINITY when none before its box ends. */
static double fog_candidate(const veil_pt_medium* m, const pt_fog* f, const double o[3], const double d[3],
                            double t0, pt_rng* rng)
{
    double a, b;
    if (m->sigma_max <= 0.0 || !veil__pt_box_clip(f->lo, f->hi, o, d, t0, INFINITY, &a, &b)) return INFINITY;
    double x[3], slope = 0.0;
    for (int k = 0; k < 3; ++k) {
        x[k] = o[k] + a * d[k];
        slope += d[k] * f->n[k];
    }
    double mslope = f->falloff * slope;          /* rho = rho_a exp(-mslope s) */
    double log_rate = log(m->sigma_max) + fog_log_density(f, x);
    double e = -log1p(-pt_uniform(rng)); /* unit exponential */
    double s;
    if (mslope == 0.0) {
        s = e * exp(-log_rate); /* homogeneous along the ray (inf: no collision) */
    } else {
        /* log |y|, y = e mslope / rate_a: in logs, so no extreme density overflows */
        double ly = log(e * fabs(mslope)) - log_rate;
        if (mslope > 0.0) { /* thinning: optical depth to infinity is rate_a / mslope */
            if (ly >= 0.0) return INFINITY;
            s = -log1p(-exp(ly)) / mslope;
        } else {            /* thickening: s = log(1 + |y|) / |mslope| */
            s = (ly > 40.0 ? ly : log1p(exp(ly))) / -mslope;
        }
    }
    double t = a + s;
    return t < b ? t : INFINITY;
}

/* ---- delta tracking -------------------------------------------------------------- */

pt_event veil__pt_free_flight(const veil_pt_medium* m, const double o[3], const double d[3], pt_rng* rng,
                              double beta[3], double* t_hit, pt_counters* c)
{
    if (m->sigma_max <= 0.0) return PT_ESCAPE;
    dda w;
    dda_init(m, o, d, 0.0, INFINITY, &w);
    double mj = 0.0, tg = grid_candidate(m, &w, rng, &mj);
    double tf[VEIL_MAX_FOGS];
    for (int i = 0; i < m->fog_count; ++i) tf[i] = fog_candidate(m, &m->fog[i], o, d, 0.0, rng);
    for (uint64_t events = 0;; ++events) {
        int who = -1; /* -1: the volume, else a fog */
        double t = tg;
        for (int i = 0; i < m->fog_count; ++i)
            if (tf[i] < t) {
                t = tf[i];
                who = i;
            }
        if (t == INFINITY) return PT_ESCAPE;
        if (events >= VEIL_PT_MAX_EVENTS) {
            ++c->cut_walks;
            return PT_CUT;
        }
        ++c->collisions;
        /* sigma_x(x) / mu per channel: the density over the majorant density */
        double frac = 1.0;
        if (who < 0) {
            double x[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
            double rho = veil_ev_sample(&m->grid, m->rho, x);
            if (rho > mj) {
                ++c->majorant_misses;
                rho = mj;
            }
            frac = rho / mj;
        }
        /* per channel: sigma_a rho / mu, sigma_s rho / mu, and the null rest */
        double a[3], sc[3], nl[3], wa = 0.0, ws = 0.0, wn = 0.0, wsum = 0.0;
        for (int k = 0; k < 3; ++k) {
            a[k] = m->sigma_a[k] * frac / m->sigma_max;
            sc[k] = m->sigma_s[k] * frac / m->sigma_max;
            nl[k] = fmax(0.0, 1.0 - a[k] - sc[k]);
            wa += beta[k] * a[k];
            ws += beta[k] * sc[k];
            wn += beta[k] * nl[k];
            wsum += beta[k];
        }
        if (!(wsum > 0.0)) return PT_ABSORB;
        double u = pt_uniform(rng) * wsum; /* event probabilities: wa, ws, wn over wsum */
        if (u < wa) return PT_ABSORB;
        if (u < wa + ws || !(wn > 0.0)) { /* (wn = 0: u only passed wa + ws by rounding) */
            for (int k = 0; k < 3; ++k) beta[k] *= sc[k] * wsum / ws;
            *t_hit = t;
            return PT_SCATTER;
        }
        for (int k = 0; k < 3; ++k) beta[k] *= nl[k] * wsum / wn;
        if (who < 0)
            tg = grid_candidate(m, &w, rng, &mj);
        else
            tf[who] = fog_candidate(m, &m->fog[who], o, d, t, rng);
    }
}

/* ---- transmittance ------------------------------------------------------------------ */

/* exp(-sigma_t D) per channel, multiplied into T; sigma_t = 0 passes all
 * light even through infinite D. */
static void attenuate(const veil_pt_medium* m, double D, double T[3])
{
    for (int k = 0; k < 3; ++k)
        if (m->sigma_t[k] > 0.0) T[k] *= exp(-m->sigma_t[k] * D);
}

/* The fogs' exact density integral over [0, len] (len may be INFINITY). */
static double fog_depth(const veil_pt_medium* m, const double o[3], const double d[3], double len)
{
    double sum = 0.0;
    for (int i = 0; i < m->fog_count; ++i) {
        const pt_fog* f = &m->fog[i];
        double a, b;
        if (!veil__pt_box_clip(f->lo, f->hi, o, d, 0.0, len, &a, &b)) continue;
        double pa[3], pb[3];
        for (int k = 0; k < 3; ++k) {
            pa[k] = o[k] + a * d[k];
            pb[k] = o[k] + b * d[k];
        }
        sum += veil_exp_fog_line_integral(f->rho0, f->falloff, f->n, f->o, pa, pb);
    }
    return sum;
}

void veil__pt_transmittance(const veil_pt_medium* m, const double o[3], const double d[3], double len,
                            pt_rng* rng, double T[3], pt_counters* c)
{
    T[0] = T[1] = T[2] = 1.0;
    if (m->sigma_max <= 0.0) return;
    attenuate(m, fog_depth(m, o, d, len), T);
    dda w;
    if (!dda_init(m, o, d, 0.0, len, &w)) return;
    double mj;
    for (uint64_t events = 0;; ++events) {
        double t = grid_candidate(m, &w, rng, &mj);
        if (t == INFINITY) return;
        if (events >= VEIL_PT_MAX_EVENTS) {
            ++c->cut_walks;
            return;
        }
        ++c->collisions;
        double x[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
        double rho = veil_ev_sample(&m->grid, m->rho, x);
        if (rho > mj) {
            ++c->majorant_misses;
            rho = mj;
        }
        double frac = rho / mj, tmax = 0.0;
        for (int k = 0; k < 3; ++k) {
            T[k] *= 1.0 - m->sigma_t[k] * frac / m->sigma_max;
            tmax = fmax(tmax, T[k]);
        }
        if (tmax <= 0.0) return;
        if (tmax < 0.1) { /* Russian roulette: survive with probability 1/2, weight 2 */
            if (pt_uniform(rng) < 0.5) {
                T[0] = T[1] = T[2] = 0.0;
                return;
            }
            for (int k = 0; k < 3; ++k) T[k] *= 2.0;
        }
    }
}

/* 2-point Gauss-Legendre on [-1, 1]: nodes +-1/sqrt(3), weights 1; exact
 * for cubics, which is what the trilinear field is along a line within one
 * cell (a product of three linear functions). */
#define GL2_NODE 0.577350269189625764509

double veil__pt_grid_depth(const veil_pt_medium* m, const double o[3], const double d[3], double t0, double t1)
{
    double a, b;
    if (!m->has_grid || !veil__pt_box_clip(m->box_lo, m->box_hi, o, d, t0, t1, &a, &b)) return 0.0;
    const veil_grid* g = &m->grid;
    const double h = g->voxel;
    const size_t nx = (size_t)g->dims[0], nxy = nx * (size_t)g->dims[1];
    double u0[3], du[3], next[3];
    int cell[3], step[3];
    for (int k = 0; k < 3; ++k) {
        /* index coordinate u = u0 + t du; cell i spans u in [i, i + 1] */
        u0[k] = (o[k] - (double)g->origin[k]) / h - 0.5;
        du[k] = d[k] / h;
        double us = u0[k] + a * du[k];
        int c = du[k] < 0.0 ? (int)ceil(us) - 1 : (int)floor(us);
        cell[k] = c < 0 ? 0 : (c > g->dims[k] - 2 ? g->dims[k] - 2 : c);
        step[k] = du[k] > 0.0 ? 1 : (du[k] < 0.0 ? -1 : 0);
        next[k] = step[k] == 0 ? INFINITY : ((double)(cell[k] + (step[k] > 0)) - u0[k]) / du[k];
    }
    double sum = 0.0, t = a;
    for (;;) {
        double tn = fmin(fmin(next[0], next[1]), fmin(next[2], b));
        if (tn > t) {
            const float* v = m->rho + (size_t)cell[2] * nxy + (size_t)cell[1] * nx + (size_t)cell[0];
            double c000 = v[0], c100 = v[1], c010 = v[nx], c110 = v[nx + 1];
            double c001 = v[nxy], c101 = v[nxy + 1], c011 = v[nxy + nx], c111 = v[nxy + nx + 1];
            double mid = 0.5 * (t + tn), half = 0.5 * (tn - t), piece = 0.0;
            for (int q = -1; q <= 1; q += 2) {
                double tq = mid + q * half * GL2_NODE, f[3];
                for (int k = 0; k < 3; ++k) {
                    f[k] = u0[k] + tq * du[k] - (double)cell[k];
                    f[k] = f[k] < 0.0 ? 0.0 : (f[k] > 1.0 ? 1.0 : f[k]); /* rounding at the faces */
                }
                double x00 = c000 + f[0] * (c100 - c000), x10 = c010 + f[0] * (c110 - c010);
                double x01 = c001 + f[0] * (c101 - c001), x11 = c011 + f[0] * (c111 - c011);
                double y0 = x00 + f[1] * (x10 - x00), y1 = x01 + f[1] * (x11 - x01);
                piece += y0 + f[2] * (y1 - y0);
            }
            sum += piece * half;
        }
        if (tn >= b) break;
        t = tn;
        for (int k = 0; k < 3; ++k) {
            if (next[k] > tn) continue;
            cell[k] += step[k];
            if (cell[k] < 0 || cell[k] > g->dims[k] - 2) return sum; /* left the box (rounding near b) */
            next[k] = ((double)(cell[k] + (step[k] > 0)) - u0[k]) / du[k];
        }
    }
    return sum;
}

void veil__pt_transmittance_exact(const veil_pt_medium* m, const double o[3], const double d[3], double len,
                                  double T[3])
{
    T[0] = T[1] = T[2] = 1.0;
    attenuate(m, fog_depth(m, o, d, len) + veil__pt_grid_depth(m, o, d, 0.0, len), T);
}

double veil__pt_scatter_pdf(const veil_pt_medium* m, const double o[3], const double d[3], const double beta0[3],
                            double t, double* rho_out, double T[3])
{
    double x[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
    double rho = veil__pt_density(m, x), num = 0.0, den = 0.0;
    *rho_out = rho;
    T[0] = T[1] = T[2] = 0.0;
    if (!(rho > 0.0)) return 0.0;
    veil__pt_transmittance_exact(m, o, d, t, T);
    for (int k = 0; k < 3; ++k) {
        num += beta0[k] * m->sigma_s[k] * T[k];
        den += beta0[k];
    }
    return den > 0.0 ? rho * num / den : 0.0;
}


void veil__pt_emission(const veil_pt_medium* m, const double o[3], const double d[3], double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    double a, b;
    if (!m->emission[0] || !m->has_grid || !veil__pt_box_clip(m->box_lo, m->box_hi, o, d, 0.0, INFINITY, &a, &b))
        return;
    const double h = 0.25 * m->grid.voxel;
    /* the optical depth from o to a: the fogs and the grid (0 before the box) */
    double D = fog_depth(m, o, d, a);
    for (double t = a; t < b;) {
        double te = fmin(t + h, b), p[3], q[3];
        for (int k = 0; k < 3; ++k) {
            p[k] = o[k] + t * d[k];
            q[k] = o[k] + 0.5 * (t + te) * d[k];
        }
        double Dstep = veil__pt_grid_depth(m, o, d, t, te) + fog_depth(m, p, d, te - t);
        for (int c = 0; c < 3; ++c) {
            double eps = veil_ev_sample(&m->grid, m->emission[c], q);
            if (!(eps > 0.0)) continue;
            double x = m->sigma_t[c] * Dstep;
            double frac = x < 1e-6 ? 1.0 - 0.5 * x : -expm1(-x) / x;
            out[c] += exp(-m->sigma_t[c] * D) * eps * (te - t) * frac;
        }
        D += Dstep;
        t = te;
    }
}
