/* veil tests — a seeded SplitMix64 stream (core/rng.h) and small vector
 * helpers shared by the reference tests (each test file gets its own stream). */
#ifndef VEIL_TEST_SEEDED_RANDOM_H
#define VEIL_TEST_SEEDED_RANDOM_H

#include <math.h>
#include <stdint.h>

#include "core/rng.h"

static uint64_t rng = 0x5eed0fu;

static inline double rnd(void) { return veil_rng_double53(&rng); } /* [0, 1), 53 bits */

static inline double rnd_in(double lo, double hi) { return lo + (hi - lo) * rnd(); }

static inline double rnd_log(double lo, double hi) { return exp(rnd_in(log(lo), log(hi))); }

static inline void rnd_unit(double v[3])
{
    double n2;
    do {
        for (int k = 0; k < 3; ++k) v[k] = rnd_in(-1.0, 1.0);
        n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    } while (n2 < 1e-4 || n2 > 1.0);
    const double s = 1.0 / sqrt(n2);
    for (int k = 0; k < 3; ++k) v[k] *= s;
}

static inline double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static inline double dist3(const double a[3], const double b[3])
{
    const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    return sqrt(dot3(d, d));
}

#endif
