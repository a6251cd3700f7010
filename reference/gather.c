#include "gather.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Phi(b) - Phi(a) for a < b, without cancellation in the tails:
 * erfc on the side of the mean they are both on. */
static double normal_mass(double a, double b)
{
    if (a >= 0.0) return 0.5 * (erfc(a / sqrt(2.0)) - erfc(b / sqrt(2.0)));
    if (b <= 0.0) return 0.5 * (erfc(-b / sqrt(2.0)) - erfc(-a / sqrt(2.0)));
    return 1.0 - 0.5 * (erfc(-a / sqrt(2.0)) + erfc(b / sqrt(2.0)));
}

double veil_gather_weight(int d, double W)
{
    if (!(W > 0.0)) return d == 0 ? 1.0 : 0.0;
    return normal_mass((d - 0.5) / W, (d + 0.5) / W);
}

veil_result veil_gather_spread(int w, int h, const float* L, const float* W, float* out, veil_error* err)
{
    size_t n = (size_t)w * (size_t)h;
    double* acc = calloc(4 * n, sizeof *acc);
    double* gx = NULL;
    size_t gcap = 0;
    if (!acc) return veil_fail(err, VEIL_ERR_OOM, "gather: out of memory");
    veil_result r = VEIL_OK;
    for (int y = 0; y < h && r == VEIL_OK; ++y) {
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            const float* l = L + 4 * i;
            if (l[0] == 0.0f && l[1] == 0.0f && l[2] == 0.0f) continue;
            double s = W[i];
            if (!(s >= 0.0) || !isfinite(s)) {
                r = veil_fail(err, VEIL_ERR_INVALID, "gather: spread %g at pixel (%d, %d)", s, x, y);
                break;
            }
            int R = (int)ceil(VEIL_GATHER_SIGMAS * s);
            if (R > w + h) R = w + h; /* nothing beyond reaches the image */
            size_t need = (size_t)(2 * R + 1);
            if (need > gcap) {
                double* g = realloc(gx, need * sizeof *g);
                if (!g) {
                    r = veil_fail(err, VEIL_ERR_OOM, "gather: out of memory");
                    break;
                }
                gx = g, gcap = need;
            }
            for (int d = -R; d <= R; ++d) gx[d + R] = veil_gather_weight(d, s);
            int y0 = y - R < 0 ? 0 : y - R, y1 = y + R >= h ? h - 1 : y + R;
            int x0 = x - R < 0 ? 0 : x - R, x1 = x + R >= w ? w - 1 : x + R;
            for (int v = y0; v <= y1; ++v) {
                double wy = gx[v - y + R];
                if (wy == 0.0) continue;
                double* row = acc + 4 * ((size_t)v * (size_t)w);
                for (int u = x0; u <= x1; ++u) {
                    double k = wy * gx[u - x + R];
                    row[4 * u + 0] += k * l[0];
                    row[4 * u + 1] += k * l[1];
                    row[4 * u + 2] += k * l[2];
                }
            }
        }
    }
    if (r == VEIL_OK)
        for (size_t i = 0; i < 4 * n; ++i) out[i] = (i % 4 == 3) ? 0.0f : (float)acc[i];
    free(acc);
    free(gx);
    return r;
}
