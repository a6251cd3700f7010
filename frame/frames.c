#include "frames.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/rng.h"

/* A whole number at *s (optional '-', digits), advancing *s; 0 when none. */
static int number(const char** s, long* out)
{
    const char* p = *s;
    int neg = *p == '-';
    if (neg) ++p;
    if (*p < '0' || *p > '9') return 0;
    long v = 0;
    while (*p >= '0' && *p <= '9') {
        if (v > VEIL_MAX_FRAME_NUMBER) return 0;
        v = v * 10 + (*p++ - '0');
    }
    if (v > VEIL_MAX_FRAME_NUMBER) return 0;
    *out = neg ? -v : v;
    *s = p;
    return 1;
}

veil_result veil_frame_range_parse(const char* text, veil_frame_range* out, veil_error* err)
{
    const char* s = text;
    veil_frame_range r = {0, 0, 1};
    int ok = number(&s, &r.first);
    r.last = r.first;
    if (ok && *s == '-') {
        ++s;
        ok = number(&s, &r.last);
        if (ok && *s == 'x') {
            ++s;
            ok = number(&s, &r.step) && r.step >= 1;
        }
    }
    if (!ok || *s)
        return veil_fail(err, VEIL_ERR_INVALID, "range '%s': expected FIRST-LAST[xSTEP] (frame numbers within "
                         "+-%ld, STEP >= 1) or one frame", text, VEIL_MAX_FRAME_NUMBER);
    if (r.last < r.first) return veil_fail(err, VEIL_ERR_INVALID, "range '%s': the last frame is before the first", text);
    if ((r.last - r.first) / r.step + 1 > VEIL_MAX_FRAMES)
        return veil_fail(err, VEIL_ERR_LIMIT, "range '%s': more than %ld frames", text, VEIL_MAX_FRAMES);
    *out = r;
    return VEIL_OK;
}

long veil_frame_range_count(const veil_frame_range* r) { return (r->last - r->first) / r->step + 1; }

long veil_frame_range_at(const veil_frame_range* r, long i) { return r->first + i * r->step; }

veil_result veil_shard_parse(const char* text, int* index, int* count, veil_error* err)
{
    char* end;
    errno = 0;
    long i = strtol(text, &end, 10), n = 0;
    int ok = !errno && end != text && *end == '/';
    if (ok) {
        const char* s = end + 1;
        n = strtol(s, &end, 10);
        ok = !errno && end != s && !*end && n >= 1 && n <= 100000 && i >= 1 && i <= n;
    }
    if (!ok) return veil_fail(err, VEIL_ERR_INVALID, "shard '%s': expected I/N with 1 <= I <= N <= 100000", text);
    *index = (int)i;
    *count = (int)n;
    return VEIL_OK;
}

/* v turned by angle about the unit axis u (Rodrigues). */
static void rotate(double v[3], const double u[3], double angle)
{
    double cs = cos(angle), sn = sin(angle), uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    double x[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    for (int a = 0; a < 3; ++a) v[a] = v[a] * cs + x[a] * sn + u[a] * uv * (1.0 - cs);
}

static int unit(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(n > 1e-12) || !isfinite(n)) return 0;
    for (int a = 0; a < 3; ++a) v[a] /= n;
    return 1;
}

veil_camera veil_orbit_camera(const veil_camera* c, const veil_orbit* o, long i, long count)
{
    veil_camera out = *c;
    double u[3] = {o->axis[0], o->axis[1], o->axis[2]}, v[3];
    if (!unit(u)) {
        for (int a = 0; a < 3; ++a) u[a] = c->up[a];
        if (!unit(u)) return out;
    } else {
        for (int a = 0; a < 3; ++a) out.up[a] = (float)u[a];
    }
    for (int a = 0; a < 3; ++a) v[a] = (double)c->position[a] - c->look_at[a];
    double deg = VEIL_PI / 180.0;
    if (o->elevation_deg != 0.0f) { /* raise towards the axis: turn about axis x v */
        double h[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        if (unit(h)) rotate(v, h, -o->elevation_deg * deg);
    }
    double angle = o->start_deg * deg + (count > 0 ? o->degrees * deg * (double)i / (double)count : 0.0);
    rotate(v, u, angle);
    for (int a = 0; a < 3; ++a) out.position[a] = (float)(c->look_at[a] + v[a]);
    return out;
}

uint32_t veil_frame_seed(uint32_t base, long frame)
{
    return (uint32_t)(veil_mix64(((uint64_t)base << 32) ^ (uint64_t)(int64_t)frame) >> 32);
}
