/* veil — the reference path tracer: camera, estimator, threads
 * (reference/pathtracer.h says what is estimated and how). */
#define _POSIX_C_SOURCE 200809L /* nanosleep, clock_gettime */
#include "pathtracer.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../scene/camera.h"
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

/* ---- one path ------------------------------------------------------------------- */

typedef struct pt_job {
    const veil_pt_medium* m;
    const veil_scene* s;
    const veil_pt_opts* o;
    double g;
    veil_camera_basis cam;
    int w, h;
    float *rgba, *se;
    atomic_int next_row, rows_done;
    atomic_uint_fast64_t collisions, cut_walks, misses, dropped;
} pt_job;

/* Light arriving at x from every light, scattered towards -dir:
 * sum over lights of E * T * phase, per channel. */
static void next_event(const pt_job* j, const double x[3], const double dir[3], pt_rng* rng, double out[3],
                       pt_counters* c)
{
    out[0] = out[1] = out[2] = 0.0;
    for (size_t l = 0; l < j->s->light_count; ++l) {
        const veil_light* L = &j->s->lights[l];
        double to[3], len, f = 1.0, travel_cos;
        if (L->type == VEIL_LIGHT_DIRECTIONAL) {
            double n = 0.0;
            for (int k = 0; k < 3; ++k) n += (double)L->direction[k] * L->direction[k];
            n = sqrt(n);
            if (!(n > 0.0)) continue;
            for (int k = 0; k < 3; ++k) to[k] = -L->direction[k] / n;
            len = INFINITY;
        } else {
            double r2 = 0.0;
            for (int k = 0; k < 3; ++k) {
                to[k] = L->position[k] - x[k];
                r2 += to[k] * to[k];
            }
            if (!(r2 > 0.0)) continue; /* at the light itself: a set of measure zero */
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
                f *= veil_spot_falloff((float)ca, cosf(L->inner_angle_deg * (float)(VEIL_PI / 180.0)),
                                       cosf(L->outer_angle_deg * (float)(VEIL_PI / 180.0)));
            }
        }
        if (!(f > 0.0) || (L->color[0] <= 0.0f && L->color[1] <= 0.0f && L->color[2] <= 0.0f)) continue;
        /* light travels along -to; the path arrived along dir and leaves towards -dir */
        travel_cos = 0.0;
        for (int k = 0; k < 3; ++k) travel_cos += -to[k] * -dir[k];
        double T[3];
        veil__pt_transmittance(j->m, x, to, len, rng, T, c);
        double ph = phase_hg(travel_cos, j->g) * f;
        for (int k = 0; k < 3; ++k) out[k] += L->color[k] * ph * T[k];
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
    for (int depth = 0;; ++depth) {
        double t;
        pt_event ev = veil__pt_free_flight(m, pos, dir, rng, beta, &t, c);
        if (ev == PT_ESCAPE) {
            if (depth == 0) memcpy(t_hat, beta, sizeof beta);
            int counts = depth == 0 ? j->o->stochastic_background
                                    : j->o->environment && (max_order == 0 || depth <= max_order);
            if (counts)
                for (int k = 0; k < 3; ++k) L[k] += beta[k] * j->s->background[k];
            return;
        }
        if (ev != PT_SCATTER) return;
        for (int k = 0; k < 3; ++k) pos[k] += t * dir[k];
        double nee[3];
        next_event(j, pos, dir, rng, nee, c);
        for (int k = 0; k < 3; ++k) L[k] += beta[k] * nee[k];
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


static void render_pixel(pt_job* j, int px, int py, pt_counters* c, uint64_t* dropped)
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
    double mean[4] = {0, 0, 0, 0}, m2[3] = {0, 0, 0};
    int count = 0;
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
        }
        mean[3] += ((th[0] + th[1] + th[2]) / 3.0 - mean[3]) / count;
    }
    double T[3];
    if (!j->o->stochastic_background) {
        veil__pt_transmittance_exact(j->m, o, d, INFINITY, T);
        for (int k = 0; k < 3; ++k) mean[k] += T[k] * j->s->background[k];
        mean[3] = (T[0] + T[1] + T[2]) / 3.0;
    }
    size_t at = (size_t)py * (size_t)j->w + (size_t)px;
    for (int k = 0; k < 3; ++k) {
        j->rgba[4 * at + k] = (float)mean[k];
        j->se[3 * at + k] = count > 1 ? (float)sqrt(m2[k] / (count - 1) / count) : 0.0f;
    }
    j->rgba[4 * at + 3] = (float)(1.0 - mean[3]);
}

static void* worker(void* arg)
{
    pt_job* j = arg;
    pt_counters c = {0, 0, 0};
    uint64_t dropped = 0;
    for (;;) {
        int y = atomic_fetch_add(&j->next_row, 1);
        if (y >= j->h) break;
        for (int x = 0; x < j->w; ++x) render_pixel(j, x, y, &c, &dropped);
        atomic_fetch_add(&j->rows_done, 1);
    }
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
    if (opts->spp < 2) return veil_fail(err, VEIL_ERR_INVALID, "spp %d: at least 2 samples per pixel (for the standard error)", opts->spp);
    if (opts->max_order < 0) return veil_fail(err, VEIL_ERR_INVALID, "max_order %d: expected >= 0", opts->max_order);
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
    j->w = w;
    j->h = h;
    j->rgba = malloc((size_t)w * (size_t)h * 4 * sizeof(float));
    j->se = malloc((size_t)w * (size_t)h * 3 * sizeof(float));
    if (!j->rgba || !j->se) {
        free(j->rgba);
        free(j->se);
        free(j);
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
    if (opts->progress) opts->progress(opts->progress_user, h, h);
    if (stats) {
        stats->ms = now_ms() - t0;
        stats->paths = (uint64_t)w * (uint64_t)h * (uint64_t)opts->spp;
        stats->collisions = atomic_load(&j->collisions);
        stats->cut_walks = atomic_load(&j->cut_walks);
        stats->majorant_misses = atomic_load(&j->misses);
        stats->dropped_samples = atomic_load(&j->dropped);
    }
    *rgba = j->rgba;
    *stderr_rgb = j->se;
    free(j);
    return VEIL_OK;
}
