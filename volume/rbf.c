#include "rbf.h"

#include <math.h>

float veil_rbf_cutoff_radius(const veil_particle* p)
{
    /* c exp(-a^2 r^2) = CUTOFF c  <=>  r = sqrt(-ln CUTOFF) / a */
    return sqrtf(-logf((float)VEIL_RBF_CUTOFF)) / p->sharpness;
}

int veil_rbf_bounds(const veil_particle* p, size_t count, float lo[3], float hi[3])
{
    if (count == 0) return 0;
    for (int k = 0; k < 3; ++k) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (size_t i = 0; i < count; ++i) {
        if (p[i].amplitude <= 0.0f) continue; /* contributes nothing */
        float rc = veil_rbf_cutoff_radius(&p[i]);
        for (int k = 0; k < 3; ++k) {
            lo[k] = fminf(lo[k], p[i].center[k] - rc);
            hi[k] = fmaxf(hi[k], p[i].center[k] + rc);
        }
    }
    return lo[0] <= hi[0];
}
