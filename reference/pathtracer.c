/* veil — the reference path tracer: camera, estimator, threads
 * (reference/pathtracer.h says what is estimated and how). */
#define _POSIX_C_SOURCE 200809L /* nanosleep, clock_gettime */
#include "pathtracer.h"

#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../scene/camera.h"
#include "../scene/environment.h"
#include "../scene/light.h"
#include "pt_internal.h"

/* Russian roulette on the path length: from this vertex on a path goes on
 * with probability PT_RR_SURVIVE (and its weight is divided by it). */
#define PT_RR_DEPTH 16
#define PT_RR_SURVIVE 0.95

/* ---- phase function ---------------------------------------------------------- */

static double phase_hg(double cos_theta, double g)
{
    double denom = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * VEIL_PI * denom * sqrt(denom));
}

/* Two unit vectors completing the unit n to an orthonormal basis. */
static void basis(const double n[3], double s[3], double t[3])
{
    double a[3] = {0.0, 0.0, 0.0};
    a[fabs(n[0]) < 0.6 ? 0 : (fabs(n[1]) < 0.6 ? 1 : 2)] = 1.0; /* an axis far from n */
    s[0] = n[1] * a[2] - n[2] * a[1];
    s[1] = n[2] * a[0] - n[0] * a[2];
    s[2] = n[0] * a[1] - n[1] * a[0];
    double l = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int k = 0; k < 3; ++k) s[k] /= l;
    t[0] = n[1] * s[2] - n[2] * s[1];
    t[1] = n[2] * s[0] - n[0] * s[2];
    t[2] = n[0] * s[1] - n[1] * s[0];
}

/* The HG density in mu = cos(theta) is (1 - g^2) / (2 (1 + g^2 - 2 g mu)^1.5);
 * its CDF from mu = -1, set equal to u1 and solved for mu, gives
 * mu = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g u1))^2) / (2 g). */
void veil_pt_sample_hg(const double dir[3], double g, double u1, double u2, double out[3])
{
    double mu;
    if (g == 0.0) {
        mu = 1.0 - 2.0 * u1;
    } else {
        double q = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
        mu = (1.0 + g * g - q * q) / (2.0 * g);
    }
    mu = mu < -1.0 ? -1.0 : (mu > 1.0 ? 1.0 : mu);
    double sin_t = sqrt(fmax(0.0, 1.0 - mu * mu)), phi = 2.0 * VEIL_PI * u2;
    double s[3], t[3];
    basis(dir, s, t);
    for (int k = 0; k < 3; ++k) out[k] = mu * dir[k] + sin_t * (cos(phi) * s[k] + sin(phi) * t[k]);
}

/* ---- equiangular sampling ------------------------------------------------------ */

int veil_pt_equiangular_init(const double o[3], const double d[3], const double light[3], double a, double b,
                             veil_pt_equiangular* e)
{
    double v[3], t0 = 0.0, r2 = 0.0, p2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        v[k] = light[k] - o[k];
        t0 += v[k] * d[k];
        r2 += v[k] * v[k];
    }
    /* the perpendicular part directly, not r^2 - t0^2, which cancels as the
     * light nears the line */
    for (int k = 0; k < 3; ++k) {
        double w = v[k] - t0 * d[k];
        p2 += w * w;
    }
    double D = sqrt(p2);
    if (!(a < b) || !(D > VEIL_PT_EQ_MIN_PERP * sqrt(r2))) return 0; /* (also NaN) */
    e->t0 = t0;
    e->D = D;
    e->a = a;
    e->b = b;
    e->theta_a = atan2(a - t0, D); /* atan2(+inf, D) = pi/2 */
    e->theta_b = atan2(b - t0, D);
    return e->theta_b > e->theta_a;
}

double veil_pt_equiangular_pdf(const veil_pt_equiangular* e, double t)
{
    if (!(t >= e->a && t <= e->b)) return 0.0;
    /* in x = (t - t0) / D, so that D^2 cannot underflow for a light near the line */
    double x = (t - e->t0) / e->D;
    return 1.0 / ((e->theta_b - e->theta_a) * e->D * (1.0 + x * x));
}

double veil_pt_equiangular_sample(const veil_pt_equiangular* e, double u, double* pdf)
{
    double th = e->theta_a + u * (e->theta_b - e->theta_a);
    double t = e->t0 + e->D * tan(th);
    /* rounding may step just outside; theta < pi/2 keeps tan finite */
    t = t < e->a ? e->a : (t > e->b ? e->b : t);
    *pdf = veil_pt_equiangular_pdf(e, t);
    return t;
}

/* ---- one path ------------------------------------------------------------------- */

typedef struct pt_job {
    const veil_pt_medium* m;
    const veil_scene* s;
    const veil_pt_opts* o;
    double g;
    int mis;               /* light_sampling resolved to MIS */
    int may_vary;          /* a sample can differ from 0 once its ray meets medium (see render_pixel) */
    int needs_collision;   /* a sample is 0 unless the camera walk collides (no equiangular light) */
    const veil_environment* env; /* the scene's environment light with its sampling tables, or NULL */
    int env_behind;        /* 1: the environment is what the camera sees behind the medium (no "background") */
    veil_camera_basis cam;
    int w, h;
    float *rgba, *se;
    atomic_int next_row, rows_done;
    atomic_uint_fast64_t collisions, cut_walks, misses, dropped;
    pthread_mutex_t lock;  /* guards sample_lo, sample_hi */
    double sample_lo[3], sample_hi[3]; /* range of single-sample values over the image */
} pt_job;

static int is_local(const veil_light* L) { return L->type == VEIL_LIGHT_POINT || L->type == VEIL_LIGHT_SPOT; }

static int is_dark(const veil_light* L) { return L->color[0] <= 0.0f && L->color[1] <= 0.0f && L->color[2] <= 0.0f; }

/* Light L arriving at x, scattered towards -dir: E * T * phase per channel
 * (0 when it cannot reach x). */
static void light_at(const pt_job* j, const veil_light* L, const double x[3], const double dir[3], pt_rng* rng,
                     double out[3], pt_counters* c)
{
    out[0] = out[1] = out[2] = 0.0;
    double to[3], len, f = 1.0, travel_cos;
    if (L->type == VEIL_LIGHT_DIRECTIONAL) {
        double n = 0.0;
        for (int k = 0; k < 3; ++k) n += (double)L->direction[k] * L->direction[k];
        n = sqrt(n);
        if (!(n > 0.0)) return;
        for (int k = 0; k < 3; ++k) to[k] = -L->direction[k] / n;
        len = INFINITY;
    } else {
        double r2 = 0.0;
        for (int k = 0; k < 3; ++k) {
            to[k] = L->position[k] - x[k];
            r2 += to[k] * to[k];
        }
        if (!(r2 > 0.0)) return; /* at the light itself: a set of measure zero */
        len = sqrt(r2);
        for (int k = 0; k < 3; ++k) to[k] /= len;
        f = 1.0 / r2;
        if (L->type == VEIL_LIGHT_SPOT) {
            double ca = 0.0, n = 0.0;
            for (int k = 0; k < 3; ++k) {
                ca -= to[k] * L->direction[k];
                n += (double)L->direction[k] * L->direction[k];
            }
            ca /= sqrt(n);
            f *= veil_spot_falloff((float)ca, veil_light_cos_inner(L), veil_light_cos_outer(L));
        }
    }
    if (!(f > 0.0) || is_dark(L)) return;
    /* light travels along -to; the path arrived along dir and leaves towards -dir */
    travel_cos = 0.0;
    for (int k = 0; k < 3; ++k) travel_cos += -to[k] * -dir[k];
    double T[3];
    veil__pt_transmittance(j->m, x, to, len, rng, T, c);
    double ph = phase_hg(travel_cos, j->g) * f;
    for (int k = 0; k < 3; ++k) out[k] = L->color[k] * ph * T[k];
}

/* One segment of a path, the ray (pos, dir) from a vertex: the equiangular
 * strategy per point/spot light (ok[l] = 0: none, so p_e = 0 and the walk's
 * next-event estimate has weight 1) and the probability prob[l] with which
 * the segment's one equiangular sample goes to light l. */
typedef struct pt_segment {
    int any;
    int ok[VEIL_MAX_LIGHTS];
    double prob[VEIL_MAX_LIGHTS];
    veil_pt_equiangular eq[VEIL_MAX_LIGHTS];
} pt_segment;

/* The light is chosen with probability proportional to its power times
 * int_a^b dt / r^2 = (theta_b - theta_a) / D, its unshadowed single
 * scattering along the segment (which is also what the equiangular sample
 * then estimates without variance from 1/r^2): one sample a segment keeps
 * the cost flat in the number of lights, and the choice is deterministic
 * given the segment, so the MIS weights below may use it. */
static void segment_init(const pt_job* j, const double pos[3], const double dir[3], pt_segment* sg)
{
    sg->any = 0;
    double a, b, sum = 0.0;
    size_t n = j->s->light_count < VEIL_MAX_LIGHTS ? j->s->light_count : VEIL_MAX_LIGHTS;
    int span = j->mis && veil__pt_medium_span(j->m, pos, dir, &a, &b);
    for (size_t l = 0; l < n; ++l) {
        const veil_light* L = &j->s->lights[l];
        sg->ok[l] = 0;
        sg->prob[l] = 0.0;
        if (!span || !is_local(L) || is_dark(L)) continue;
        double p[3] = {L->position[0], L->position[1], L->position[2]};
        sg->ok[l] = veil_pt_equiangular_init(pos, dir, p, a, b, &sg->eq[l]);
        if (!sg->ok[l]) continue;
        double power = fmax(L->color[0], 0.0f) + fmax(L->color[1], 0.0f) + fmax(L->color[2], 0.0f);
        sg->prob[l] = power * (sg->eq[l].theta_b - sg->eq[l].theta_a) / sg->eq[l].D;
        sum += sg->prob[l];
    }
    int usable = sum > 0.0 && sum < INFINITY; /* (overflow: no equiangular strategy on this segment) */
    for (size_t l = 0; l < n; ++l) {
        sg->prob[l] = usable ? sg->prob[l] / sum : 0.0;
        sg->ok[l] = sg->prob[l] > 0.0;
        sg->any |= sg->ok[l];
    }
}

/* Strategy (e) on one segment: a light l chosen with probability P_l, a
 * point t_e ~ p_e,l and beta0 T sigma_s Lnee / (P_l p_e + q_d) added to L
 * (f / (P_l p_e) times the balance weight; pathtracer.h). T exact, so that
 * T / q_d, and with it the estimate, stays bounded however thick the
 * medium (an unbiased but noisy T here, ratio tracking, left fireflies
 * where T << 0.1). The transmittance, the costly part, is computed last,
 * only when the rest is not 0. */
static void equiangular_light(const pt_job* j, const pt_segment* sg, const double pos[3], const double dir[3],
                              const double beta0[3], pt_rng* rng, double L[3], pt_counters* c)
{
    const veil_pt_medium* m = j->m;
    size_t n = j->s->light_count < VEIL_MAX_LIGHTS ? j->s->light_count : VEIL_MAX_LIGHTS, l = 0, last = 0;
    double u = pt_uniform(rng), acc = 0.0;
    for (; l < n; ++l) { /* inverse CDF over the lights; rounding falls to the last one that can be chosen */
        if (!sg->ok[l]) continue;
        last = l;
        acc += sg->prob[l];
        if (u < acc) break;
    }
    if (l >= n) l = last;
    double pe, rho, T[3], nee[3];
    double t = veil_pt_equiangular_sample(&sg->eq[l], pt_uniform(rng), &pe);
    double x[3] = {pos[0] + t * dir[0], pos[1] + t * dir[1], pos[2] + t * dir[2]};
    if (!(pe > 0.0) || !(veil__pt_density(m, x) > 0.0)) return; /* empty space: f = 0 */
    light_at(j, &j->s->lights[l], x, dir, rng, nee, c);
    if (!(nee[0] > 0.0 || nee[1] > 0.0 || nee[2] > 0.0)) return;
    double qd = veil__pt_scatter_pdf(m, pos, dir, beta0, t, &rho, T);
    double inv = 1.0 / (sg->prob[l] * pe + qd);
    for (int k = 0; k < 3; ++k) L[k] += beta0[k] * T[k] * m->sigma_s[k] * rho * nee[k] * inv;
}

/* Strategy (d) and the directional lights, at the walk's scattering point
 * x = pos + t dir of the segment sg: every light's next-event estimate,
 * times beta (the throughput after the collision) and the MIS weight
 * w_d = q_d / (q_d + P_l p_e) where the segment has an equiangular strategy
 * for the light (1 elsewhere). */
static void next_event(const pt_job* j, const pt_segment* sg, const double pos[3], const double dir[3], double t,
                       const double beta0[3], const double beta[3], pt_rng* rng, double L[3], pt_counters* c)
{
    double x[3] = {pos[0] + t * dir[0], pos[1] + t * dir[1], pos[2] + t * dir[2]};
    double qd = -1.0; /* computed on first need */
    for (size_t l = 0; l < j->s->light_count; ++l) {
        double nee[3], w = 1.0;
        light_at(j, &j->s->lights[l], x, dir, rng, nee, c);
        if (!(nee[0] > 0.0 || nee[1] > 0.0 || nee[2] > 0.0)) continue;
        if (l < VEIL_MAX_LIGHTS && sg->ok[l]) {
            if (qd < 0.0) {
                double rho, T[3];
                qd = veil__pt_scatter_pdf(j->m, pos, dir, beta0, t, &rho, T);
            }
            double pe = sg->prob[l] * veil_pt_equiangular_pdf(&sg->eq[l], t);
            w = qd > 0.0 ? qd / (qd + pe) : (pe > 0.0 ? 0.0 : 1.0);
        }
        for (int k = 0; k < 3; ++k) L[k] += beta[k] * w * nee[k];
    }
}

/* The environment light at the walk's scattering vertex x, the path arriving along dir, times beta: two
 * samples, one of the map (luminance x solid angle, scene/environment.h) and one of the phase function,
 * each with its transmittance to infinity (ratio tracking) and combined by the power heuristic
 * (Veach 1997): w_s = p_s^2 / (p_e^2 + p_p^2) for the strategy s that drew the direction. A sun in the map
 * is found by the map's samples, a smooth sky seen through a peaked phase function by the phase's. Both
 * are taken here, at the vertex, rather than the phase's one when the walk escapes: so every order the
 * walk reaches, the last included, gets both (the walk stops at max_order). */
static void environment_at(const pt_job* j, const double x[3], const double dir[3], const double beta[3], pt_rng* rng,
                           double L[3], pt_counters* c)
{
    const veil_environment* env = j->env;
    double w[3], T[3], Le[3];
    /* (a) the map (with light_sampling DISTANCE, the phase function's sample alone, weight 1: the check that
     * the map's sampling and its pdf are right, an estimator without them of the same value) */
    const int both = j->mis;
    if (both) {
        double pe = veil_env_sample(env, pt_uniform(rng), pt_uniform(rng), pt_uniform(rng), w);
        double pp = phase_hg(w[0] * dir[0] + w[1] * dir[1] + w[2] * dir[2], j->g);
        veil_env_radiance(env, w, Le);
        if ((Le[0] > 0.0 || Le[1] > 0.0 || Le[2] > 0.0) && pe > 0.0) {
            veil__pt_transmittance(j->m, x, w, INFINITY, rng, T, c);
            double f = pp / pe * (pe * pe / (pe * pe + pp * pp));
            for (int k = 0; k < 3; ++k) L[k] += beta[k] * Le[k] * T[k] * f;
        }
    }
    /* (b) the phase function: its value over its pdf is 1 */
    veil_pt_sample_hg(dir, j->g, pt_uniform(rng), pt_uniform(rng), w);
    double pp = phase_hg(w[0] * dir[0] + w[1] * dir[1] + w[2] * dir[2], j->g);
    double pe = both ? veil_env_pdf(env, w) : 0.0;
    veil_env_radiance(env, w, Le);
    if ((Le[0] > 0.0 || Le[1] > 0.0 || Le[2] > 0.0) && pp > 0.0) {
        veil__pt_transmittance(j->m, x, w, INFINITY, rng, T, c);
        double f = pp * pp / (pe * pe + pp * pp);
        for (int k = 0; k < 3; ++k) L[k] += beta[k] * Le[k] * T[k] * f;
    }
}

/* One sample of the radiance along the camera ray (o, d); *t_hat gets the
 * estimate of the camera ray's transmittance per channel (stochastic
 * background only). */
static void trace(const pt_job* j, const double o[3], const double d[3], pt_rng* rng, double L[3], double t_hat[3],
                  pt_counters* c)
{
    const veil_pt_medium* m = j->m;
    double beta[3] = {1.0, 1.0, 1.0}, pos[3], dir[3];
    memcpy(pos, o, sizeof pos);
    memcpy(dir, d, sizeof dir);
    L[0] = L[1] = L[2] = 0.0;
    t_hat[0] = t_hat[1] = t_hat[2] = 0.0;
    const int max_order = j->o->max_order;
    /* Reaching depth d means d < max_order (or unlimited), so a scattering
     * on this segment, of order d + 1, counts: the equiangular vertex as
     * much as the walk's own. */
    for (int depth = 0;; ++depth) {
        double t, beta0[3];
        memcpy(beta0, beta, sizeof beta0);
        pt_segment sg;
        segment_init(j, pos, dir, &sg);
        /* emission along this segment reaches the vertex after `depth` scatterings */
        if (m->emission[0] && (max_order == 0 || depth <= max_order)) {
            double e[3];
            veil__pt_emission(m, pos, dir, e);
            for (int k = 0; k < 3; ++k) L[k] += beta0[k] * e[k];
        }
        /* (e) whatever the walk does next on this segment: it is a second,
         * independent estimate of the same integral */
        if (sg.any) equiangular_light(j, &sg, pos, dir, beta0, rng, L, c);
        pt_event ev = veil__pt_free_flight(m, pos, dir, rng, beta, &t, c);
        if (ev == PT_ESCAPE) {
            if (depth == 0) memcpy(t_hat, beta, sizeof beta);
            int counts = depth == 0 ? j->o->stochastic_background
                                    : j->o->environment && (max_order == 0 || depth <= max_order);
            if (counts && depth == 0 && j->env_behind) {
                double Le[3];
                veil_env_radiance(j->env, dir, Le);
                for (int k = 0; k < 3; ++k) L[k] += beta[k] * Le[k];
            } else if (counts)
                for (int k = 0; k < 3; ++k) L[k] += beta[k] * j->s->background[k];
            return;
        }
        if (ev != PT_SCATTER) return;
        next_event(j, &sg, pos, dir, t, beta0, beta, rng, L, c);
        if (j->env) {
            double x[3] = {pos[0] + t * dir[0], pos[1] + t * dir[1], pos[2] + t * dir[2]};
            environment_at(j, x, dir, beta, rng, L, c);
        }
        for (int k = 0; k < 3; ++k) pos[k] += t * dir[k];
        if (max_order > 0 && depth + 1 >= max_order) return;
        if (depth + 1 >= PT_RR_DEPTH) {
            if (pt_uniform(rng) >= PT_RR_SURVIVE) return;
            for (int k = 0; k < 3; ++k) beta[k] /= PT_RR_SURVIVE;
        }
        double u1 = pt_uniform(rng), u2 = pt_uniform(rng), nd[3];
        veil_pt_sample_hg(dir, j->g, u1, u2, nd);
        memcpy(dir, nd, sizeof dir);
    }
}

/* ---- pixels and threads -------------------------------------------------------- */

/* A channel whose samples were all equal but could have varied is written
 * as -sqrt(p / n), a mark that veil_pt_render turns into the bound of
 * pathtracer.h once the whole image's sample range is known. */
static void render_pixel(pt_job* j, int px, int py, pt_counters* c, uint64_t* dropped, double lo[3], double hi[3])
{
    float df[3];
    veil_camera_ray(&j->cam, j->w, j->h, px, py, df);
    double o[3], d[3], n = 0.0;
    for (int k = 0; k < 3; ++k) {
        o[k] = j->cam.pos[k];
        d[k] = df[k];
        n += d[k] * d[k];
    }
    for (int k = 0; k < 3; ++k) d[k] /= sqrt(n);
    pt_rng rng = {veil_mix64(j->o->seed * VEIL_RNG_GAMMA + veil_mix64((uint64_t)py * (uint64_t)j->w + (uint64_t)px))};
    /* Welford's running mean and sum of squared deviations, per channel and for T */
    double mean[4] = {0, 0, 0, 0}, m2[3] = {0, 0, 0}, first[3] = {0, 0, 0};
    int count = 0, same[3] = {1, 1, 1};
    for (int s = 0; s < j->o->spp; ++s) {
        double L[3], th[3];
        trace(j, o, d, &rng, L, th, c);
        if (!(isfinite(L[0]) && isfinite(L[1]) && isfinite(L[2]) && isfinite(th[0] + th[1] + th[2]))) {
            ++*dropped;
            continue;
        }
        ++count;
        for (int k = 0; k < 3; ++k) {
            double delta = L[k] - mean[k];
            mean[k] += delta / count;
            m2[k] += delta * (L[k] - mean[k]);
            if (count == 1) first[k] = L[k];
            same[k] &= L[k] == first[k]; /* exact: m2 may round to a tiny non-zero */
            lo[k] = fmin(lo[k], L[k]);
            hi[k] = fmax(hi[k], L[k]);
        }
        mean[3] += ((th[0] + th[1] + th[2]) / 3.0 - mean[3]) / count;
    }
    double T[3];
    veil__pt_transmittance_exact(j->m, o, d, INFINITY, T);
    if (!j->o->stochastic_background) {
        double behind[3] = {j->s->background[0], j->s->background[1], j->s->background[2]};
        if (j->env_behind) veil_env_radiance(j->env, d, behind);
        for (int k = 0; k < 3; ++k) mean[k] += T[k] * behind[k];
        mean[3] = (T[0] + T[1] + T[2]) / 3.0;
    }
    /* a sample is 0 (or the background estimate 1 * background) for sure
     * when the camera ray meets no medium: no collision can happen */
    int may_vary = j->may_vary && (T[0] < 1.0 || T[1] < 1.0 || T[2] < 1.0);
    /* channels with all samples equal: p, the chance that a sample differs,
     * by the rule of three, or by the walk's collision probability where a
     * sample without a collision is surely 0 (pathtracer.h); the factor
     * sqrt(p / n) waits, negated, for the image's range */
    double n_eff = count > 1 ? count : 1, p = 3.0 / n_eff;
    if (j->needs_collision) p = fmin(p, 1.0 - (T[0] + T[1] + T[2]) / 3.0);
    float pending = -(float)fmax(sqrt(p / n_eff), FLT_MIN); /* < 0 even where p / n underflows a float */
    size_t at = (size_t)py * (size_t)j->w + (size_t)px;
    for (int k = 0; k < 3; ++k) {
        j->rgba[4 * at + k] = (float)mean[k];
        if (count > 1 && !same[k])
            j->se[3 * at + k] = (float)sqrt(m2[k] / (count - 1) / count);
        else
            j->se[3 * at + k] = may_vary ? pending : 0.0f;
    }
    j->rgba[4 * at + 3] = (float)(1.0 - mean[3]);
}

static void* worker(void* arg)
{
    pt_job* j = arg;
    pt_counters c = {0, 0, 0};
    uint64_t dropped = 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (;;) {
        int y = atomic_fetch_add(&j->next_row, 1);
        if (y >= j->h) break;
        for (int x = 0; x < j->w; ++x) render_pixel(j, x, y, &c, &dropped, lo, hi);
        atomic_fetch_add(&j->rows_done, 1);
    }
    pthread_mutex_lock(&j->lock);
    for (int k = 0; k < 3; ++k) {
        j->sample_lo[k] = fmin(j->sample_lo[k], lo[k]);
        j->sample_hi[k] = fmax(j->sample_hi[k], hi[k]);
    }
    pthread_mutex_unlock(&j->lock);
    atomic_fetch_add(&j->collisions, c.collisions);
    atomic_fetch_add(&j->cut_walks, c.cut_walks);
    atomic_fetch_add(&j->misses, c.majorant_misses);
    atomic_fetch_add(&j->dropped, dropped);
    return NULL;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

#define PT_MAX_THREADS 256

veil_result veil_pt_render(const veil_pt_medium* m, const veil_scene* s, const veil_pt_opts* opts, float** rgba,
                           float** stderr_rgb, veil_pt_stats* stats, veil_error* err)
{
    *rgba = NULL;
    *stderr_rgb = NULL;
    const veil_camera* cam = opts->camera ? opts->camera : &s->camera;
    int w = opts->width > 0 ? opts->width : cam->width, h = opts->height > 0 ? opts->height : cam->height;
    if (w < 1 || h < 1 || w > VEIL_SCENE_MAX_IMAGE || h > VEIL_SCENE_MAX_IMAGE)
        return veil_fail(err, VEIL_ERR_INVALID, "image size %dx%d is outside 1..%d", w, h, VEIL_SCENE_MAX_IMAGE);
    if (cam->clip[0] > 0.0f || cam->clip[1] > 0.0f) /* the camera walk starts at the eye and never ends early */
        return veil_fail(err, VEIL_ERR_INVALID, "camera.clip: the reference path tracer has no clip planes (the "
                         "march has); remove camera.clip to compare with it");
    if (opts->spp < 2) return veil_fail(err, VEIL_ERR_INVALID, "spp %d: at least 2 samples per pixel (for the standard error)", opts->spp);
    if (opts->max_order < 0) return veil_fail(err, VEIL_ERR_INVALID, "max_order %d: expected >= 0", opts->max_order);
    int sampling = opts->light_sampling == VEIL_PT_LIGHT_SAMPLING_DEFAULT ? VEIL_PT_LIGHT_SAMPLING_MIS
                                                                          : opts->light_sampling;
    if (sampling != VEIL_PT_LIGHT_SAMPLING_DISTANCE && sampling != VEIL_PT_LIGHT_SAMPLING_MIS)
        return veil_fail(err, VEIL_ERR_INVALID, "light_sampling %d: expected 0 (default), %d (distance) or %d (MIS)",
                         opts->light_sampling, VEIL_PT_LIGHT_SAMPLING_DISTANCE, VEIL_PT_LIGHT_SAMPLING_MIS);
    pt_job* j = calloc(1, sizeof *j);
    if (!j) return veil_fail(err, VEIL_ERR_OOM, "out of memory");
    veil_result r = veil_camera_make_basis(cam, w, h, &j->cam, err);
    if (r != VEIL_OK) {
        free(j);
        return r;
    }
    j->m = m;
    j->s = s;
    j->o = opts;
    j->g = s->medium.phase.type == VEIL_PHASE_HG ? s->medium.phase.g : 0.0;
    j->mis = sampling == VEIL_PT_LIGHT_SAMPLING_MIS;
    /* emission: scattered emission varies, and direct emission needs no collision */
    j->may_vary = opts->environment || opts->stochastic_background || m->emission[0] != NULL;
    veil_environment env; /* the scene's, with sampling tables of its own (s is the caller's, const) */
    memset(&env, 0, sizeof env);
    if (s->environment.present) {
        if (opts->environment) {
            free(j);
            return veil_fail(err, VEIL_ERR_INVALID, "the scene has an environment light (lights[%zu]): the "
                             "background cannot light the medium as well", s->environment.light_index);
        }
        env = s->environment;
        env.dist = NULL;
        r = veil_env_dist_make(&env, err);
        if (r != VEIL_OK) {
            free(j);
            return r;
        }
        j->env = &env;
        j->env_behind = !s->background_set;
        j->may_vary = 1;
    }
    j->needs_collision = !opts->stochastic_background && m->emission[0] == NULL;
    for (size_t l = 0; l < s->light_count; ++l) {
        j->may_vary |= !is_dark(&s->lights[l]);
        /* an equiangular sample lights a sample without any collision */
        if (j->mis && is_local(&s->lights[l]) && !is_dark(&s->lights[l])) j->needs_collision = 0;
    }
    for (int k = 0; k < 3; ++k) {
        j->sample_lo[k] = INFINITY;
        j->sample_hi[k] = -INFINITY;
    }
    j->w = w;
    j->h = h;
    j->rgba = malloc((size_t)w * (size_t)h * 4 * sizeof(float));
    j->se = malloc((size_t)w * (size_t)h * 3 * sizeof(float));
    if (!j->rgba || !j->se || pthread_mutex_init(&j->lock, NULL) != 0) {
        free(j->rgba);
        free(j->se);
        free(j);
        veil_env_dist_free(&env);
        return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %dx%d image", w, h);
    }
    double t0 = now_ms();
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int n = opts->threads > 0 ? opts->threads : (int)(cores > 0 ? cores : 1);
    if (n > PT_MAX_THREADS) n = PT_MAX_THREADS;
    if (n > h) n = h;
    pthread_t th[PT_MAX_THREADS];
    int started = 0;
    for (; started < n; ++started)
        if (pthread_create(&th[started], NULL, worker, j) != 0) break;
    if (started == 0) worker(j); /* no threads to be had: do it here */
    while (opts->progress && started > 0 && atomic_load(&j->rows_done) < h) {
        opts->progress(opts->progress_user, atomic_load(&j->rows_done), h);
        struct timespec ts = {0, 200 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
    for (int i = 0; i < started; ++i) pthread_join(th[i], NULL);
    pthread_mutex_destroy(&j->lock);
    /* the unresolved channels (marked -sqrt(p / n)): R_c sqrt(p / n), pathtracer.h */
    uint64_t unresolved = 0;
    double range[3];
    for (int k = 0; k < 3; ++k)
        range[k] = j->sample_hi[k] >= j->sample_lo[k] ? j->sample_hi[k] - j->sample_lo[k] : 0.0;
    for (size_t i = 0; i < (size_t)w * (size_t)h; ++i) {
        int marked = 0;
        for (int k = 0; k < 3; ++k) {
            float* e = &j->se[3 * i + (size_t)k];
            if (*e < 0.0f) {
                *e = (float)fmin(range[k] * -(double)*e, FLT_MAX); /* finite, as promised */
                marked = 1;
            }
        }
        unresolved += (uint64_t)marked;
        if (opts->unresolved) opts->unresolved[i] = (unsigned char)marked;
    }
    if (opts->progress) opts->progress(opts->progress_user, h, h);
    if (stats) {
        stats->ms = now_ms() - t0;
        stats->paths = (uint64_t)w * (uint64_t)h * (uint64_t)opts->spp;
        stats->collisions = atomic_load(&j->collisions);
        stats->cut_walks = atomic_load(&j->cut_walks);
        stats->majorant_misses = atomic_load(&j->misses);
        stats->dropped_samples = atomic_load(&j->dropped);
        stats->unresolved_pixels = unresolved;
        stats->light_sampling = sampling;
    }
    *rgba = j->rgba;
    *stderr_rgb = j->se;
    free(j);
    veil_env_dist_free(&env);
    return VEIL_OK;
}
