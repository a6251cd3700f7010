/* veil — the per-voxel updates of every optical-depth scheme, written once
 * for C and GLSL (see core/shared.glsl.h for the portability macros). The
 * shaders and the C reference implementations include this file, so each
 * scheme does exactly the same float operations on the CPU and the GPU.
 *
 * Index space: voxel (i,j,k)'s centre is the point (i,j,k); the medium
 * spans [0, n-1] per axis (volume/volume.h); h is the voxel edge (m). D is
 * the density integral from a voxel centre to the light (density·m).
 *
 * The includer defines, before including:
 *   VEIL_CTX_PARAM / VEIL_CTX_ARG  a leading parameter/argument carrying its
 *                                  data (empty in GLSL)
 *   VEIL_DIMS(a)        grid size along axis a (int)
 *   VEIL_RHO(i,j,k)     density of voxel (i,j,k)
 *   VEIL_DIN(i,j,k)     D of voxel (i,j,k) as far as computed (the previous
 *                       Jacobi step, or the current texture in a sweep)
 *
 * Lights: `type` VEIL_LIGHT_DIRECTIONAL uses L = unit vector toward the
 * light; otherwise L = the light's position in index space and c = its
 * voxel, c_a = floor(L_a + 1/2) (passed in, computed in double by the caller).
 */
#ifndef VEIL_OPV_SCHEMES_GLSL_H
#define VEIL_OPV_SCHEMES_GLSL_H

/* Points this many samples along the segment to a light in the near field
 * (the voxels within 2 of a point light, L-infinity): midpoint rule. */
#define VEIL_NEAR_SAMPLES 16

/* Trilinear density at index-space point p, clamped into the medium's box
 * (for points that rounding put just outside). */
VEIL_FN float veil_rho_clamped(VEIL_CTX_PARAM float p0, float p1, float p2)
{
    int lo[3], hi[3];
    float f[3];
    float p[3];
    p[0] = p0;
    p[1] = p1;
    p[2] = p2;
    for (int a = 0; a < 3; ++a) {
        float q = VEIL_MINF(VEIL_MAXF(p[a], 0.0f), VEIL_FLOAT(VEIL_DIMS(a) - 1));
        float fl = VEIL_FLOORF(q);
        lo[a] = VEIL_INT(fl);
        hi[a] = lo[a] + 1 < VEIL_DIMS(a) ? lo[a] + 1 : lo[a];
        f[a] = q - fl;
    }
    VEIL_PRECISE float c00 = VEIL_RHO(lo[0], lo[1], lo[2]) * (1.0f - f[0]) + VEIL_RHO(hi[0], lo[1], lo[2]) * f[0];
    VEIL_PRECISE float c10 = VEIL_RHO(lo[0], hi[1], lo[2]) * (1.0f - f[0]) + VEIL_RHO(hi[0], hi[1], lo[2]) * f[0];
    VEIL_PRECISE float c01 = VEIL_RHO(lo[0], lo[1], hi[2]) * (1.0f - f[0]) + VEIL_RHO(hi[0], lo[1], hi[2]) * f[0];
    VEIL_PRECISE float c11 = VEIL_RHO(lo[0], hi[1], hi[2]) * (1.0f - f[0]) + VEIL_RHO(hi[0], hi[1], hi[2]) * f[0];
    VEIL_PRECISE float c0 = c00 * (1.0f - f[1]) + c10 * f[1];
    VEIL_PRECISE float c1 = c01 * (1.0f - f[1]) + c11 * f[1];
    VEIL_PRECISE float r = c0 * (1.0f - f[2]) + c1 * f[2];
    return r;
}

/* As above, but 0 outside the box: the medium's density at p. */
VEIL_FN float veil_rho_at(VEIL_CTX_PARAM float p0, float p1, float p2)
{
    if (p0 < 0.0f || p1 < 0.0f || p2 < 0.0f || p0 > VEIL_FLOAT(VEIL_DIMS(0) - 1) ||
        p1 > VEIL_FLOAT(VEIL_DIMS(1) - 1) || p2 > VEIL_FLOAT(VEIL_DIMS(2) - 1))
        return 0.0f;
    return veil_rho_clamped(VEIL_CTX_ARG p0, p1, p2);
}

/* The axis-neighbour gather (the published scheme): the cosine-weighted
 * mean over up-wind axis neighbours N of D(N) + step density. The step's
 * density is the trapezoid (rho(X) + rho(N)) / 2 times a length: one voxel
 * (published; Manhattan in effect), or, `corrected`, h |d|_2 / sum|d_a| over
 * the up-wind axes, the expected Euclidean progress of a step (exact on the
 * axes and on average). A voxel with an up-wind neighbour outside the grid
 * lies on a face of the medium that the light enters by: D = 0. In the
 * light's own voxel D = rho(X) h |d|. */
VEIL_FN float veil_gather_cell(VEIL_CTX_PARAM int x0, int x1, int x2, int type, float l0, float l1, float l2,
                               int c0, int c1, int c2, float h, int corrected)
{
    int x[3], c[3];
    VEIL_PRECISE float d[3];
    x[0] = x0; x[1] = x1; x[2] = x2;
    c[0] = c0; c[1] = c1; c[2] = c2;
    d[0] = type == VEIL_LIGHT_DIRECTIONAL ? l0 : l0 - VEIL_FLOAT(x0);
    d[1] = type == VEIL_LIGHT_DIRECTIONAL ? l1 : l1 - VEIL_FLOAT(x1);
    d[2] = type == VEIL_LIGHT_DIRECTIONAL ? l2 : l2 - VEIL_FLOAT(x2);
    bool valid[3];
    VEIL_PRECISE float wsum = 0.0f;
    for (int a = 0; a < 3; ++a) {
        valid[a] = type == VEIL_LIGHT_DIRECTIONAL ? d[a] != 0.0f : x[a] != c[a];
        if (valid[a]) wsum += VEIL_ABSF(d[a]);
    }
    float r = VEIL_RHO(x0, x1, x2);
    VEIL_PRECISE float len = VEIL_SQRTF(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!valid[0] && !valid[1] && !valid[2]) {
        VEIL_PRECISE float own = r * (h * len);
        return own;
    }
    VEIL_PRECISE float step = corrected != 0 ? h * (len / wsum) : h;
    VEIL_PRECISE float acc = 0.0f;
    for (int a = 0; a < 3; ++a) {
        if (!valid[a]) continue;
        int n[3];
        n[0] = x0; n[1] = x1; n[2] = x2;
        n[a] += d[a] > 0.0f ? 1 : -1;
        if (n[a] < 0 || n[a] >= VEIL_DIMS(a)) return 0.0f;
        VEIL_PRECISE float term = VEIL_DIN(n[0], n[1], n[2]) + 0.5f * step * (r + VEIL_RHO(n[0], n[1], n[2]));
        acc += (VEIL_ABSF(d[a]) / wsum) * term;
    }
    return acc;
}

/* Near field of a point light: D by the midpoint rule along the straight
 * segment (VEIL_NEAR_SAMPLES samples), density 0 outside the box. */
VEIL_FN float veil_near_cell(VEIL_CTX_PARAM int x0, int x1, int x2, float l0, float l1, float l2, float h)
{
    VEIL_PRECISE float e0 = l0 - VEIL_FLOAT(x0), e1 = l1 - VEIL_FLOAT(x1), e2 = l2 - VEIL_FLOAT(x2);
    VEIL_PRECISE float sum = 0.0f;
    for (int k = 0; k < VEIL_NEAR_SAMPLES; ++k) {
        VEIL_PRECISE float t = (VEIL_FLOAT(k) + 0.5f) / VEIL_FLOAT(VEIL_NEAR_SAMPLES);
        sum += veil_rho_at(VEIL_CTX_ARG VEIL_FLOAT(x0) + e0 * t, VEIL_FLOAT(x1) + e1 * t, VEIL_FLOAT(x2) + e2 * t);
    }
    VEIL_PRECISE float len = VEIL_SQRTF(e0 * e0 + e1 * e1 + e2 * e2);
    VEIL_PRECISE float D = h * len * (sum / VEIL_FLOAT(VEIL_NEAR_SAMPLES));
    return D;
}

/* The axis a semi-Lagrangian step takes: a sun's dominant axis (the first
 * largest |l_a|); for a point light, among the axes with the largest
 * |x_a - c_a|, the one with the largest real offset |l_a - x_a| (then the
 * first). See propagate/opv_plan.h for why this order is safe. */
VEIL_FN int veil_sl_axis(int x0, int x1, int x2, int type, float l0, float l1, float l2, int c0, int c1, int c2)
{
    float e[3];
    int dist[3];
    e[0] = type == VEIL_LIGHT_DIRECTIONAL ? l0 : l0 - VEIL_FLOAT(x0);
    e[1] = type == VEIL_LIGHT_DIRECTIONAL ? l1 : l1 - VEIL_FLOAT(x1);
    e[2] = type == VEIL_LIGHT_DIRECTIONAL ? l2 : l2 - VEIL_FLOAT(x2);
    dist[0] = type == VEIL_LIGHT_DIRECTIONAL ? 0 : (x0 > c0 ? x0 - c0 : c0 - x0);
    dist[1] = type == VEIL_LIGHT_DIRECTIONAL ? 0 : (x1 > c1 ? x1 - c1 : c1 - x1);
    dist[2] = type == VEIL_LIGHT_DIRECTIONAL ? 0 : (x2 > c2 ? x2 - c2 : c2 - x2);
    int a = 0;
    for (int b = 1; b < 3; ++b)
        if (dist[b] > dist[a] || (dist[b] == dist[a] && VEIL_ABSF(e[b]) > VEIL_ABSF(e[a]))) a = b;
    return a;
}

/* Where the path from voxel y to the light ends: 6 + 0 at a point light,
 * else 2 b + (e_b > 0) for the face of the medium it leaves by (first
 * axis on ties). D is smooth where this is constant and has a kink where
 * it changes. */
VEIL_FN int veil_path_end(VEIL_CTX_PARAM int y0, int y1, int y2, int type, float l0, float l1, float l2)
{
    float e[3];
    int y[3];
    y[0] = y0; y[1] = y1; y[2] = y2;
    e[0] = type == VEIL_LIGHT_DIRECTIONAL ? l0 : l0 - VEIL_FLOAT(y0);
    e[1] = type == VEIL_LIGHT_DIRECTIONAL ? l1 : l1 - VEIL_FLOAT(y1);
    e[2] = type == VEIL_LIGHT_DIRECTIONAL ? l2 : l2 - VEIL_FLOAT(y2);
    float best = type == VEIL_LIGHT_DIRECTIONAL ? 3.0e38f : 1.0f;
    int end = 6;
    for (int b = 0; b < 3; ++b) {
        if (e[b] == 0.0f) continue;
        float face = e[b] > 0.0f ? VEIL_FLOAT(VEIL_DIMS(b) - 1) : 0.0f;
        float tb = (face - VEIL_FLOAT(y[b])) / e[b];
        if (tb < best) {
            best = tb;
            end = 2 * b + (e[b] > 0.0f ? 1 : 0);
        }
    }
    return end;
}

/* Semi-Lagrangian up-wind step with characteristics `k` voxels long: follow
 * the true direction e toward the light from X to the voxel plane k voxels
 * away along axis a, integrating the density on the way (one trapezoid per
 * voxel along a), and add D there, read bilinearly from the four voxels
 * around the crossing point. k = 1 is the classic short characteristic;
 * a longer one interpolates k times less often, so it diffuses sharp
 * shadows and the kinks of D (where neighbouring rays enter the medium
 * through different faces) k times less, at k density samples a voxel.
 * If the crossing point would lie within `exit_steps` voxels (along a) of
 * where the path ends (the medium's face, or a point light: where D has a
 * kink or a cone's apex, badly interpolated), D is integrated to the end
 * instead.
 * Needs |e_b| <= |e_a| and |e_a| >= 1 (what veil_sl_axis guarantees outside
 * the near field); the crossing point is also clamped to within k voxels
 * of X. See propagate/opv_plan.h for why the order is safe. */
VEIL_FN float veil_sl_cell(VEIL_CTX_PARAM int x0, int x1, int x2, int a, int type, float l0, float l1, float l2,
                           float h, int k, float exit_steps)
{
    int x[3];
    VEIL_PRECISE float e[3];
    x[0] = x0; x[1] = x1; x[2] = x2;
    e[0] = type == VEIL_LIGHT_DIRECTIONAL ? l0 : l0 - VEIL_FLOAT(x0);
    e[1] = type == VEIL_LIGHT_DIRECTIONAL ? l1 : l1 - VEIL_FLOAT(x1);
    e[2] = type == VEIL_LIGHT_DIRECTIONAL ? l2 : l2 - VEIL_FLOAT(x2);
    VEIL_PRECISE float t_voxel = 1.0f / VEIL_ABSF(e[a]); /* one voxel along a */
    /* where the path ends: a point light at t = 1, or the medium's face */
    VEIL_PRECISE float t_end = type == VEIL_LIGHT_DIRECTIONAL ? 3.0e38f : 1.0f;
    for (int b = 0; b < 3; ++b) {
        if (e[b] == 0.0f) continue;
        VEIL_PRECISE float face = e[b] > 0.0f ? VEIL_FLOAT(VEIL_DIMS(b) - 1) : 0.0f;
        VEIL_PRECISE float tb = (face - VEIL_FLOAT(x[b])) / e[b];
        t_end = VEIL_MINF(t_end, tb);
    }
    t_end = VEIL_MAXF(t_end, 0.0f);
    VEIL_PRECISE float len = VEIL_SQRTF(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    bool direct = t_end <= (VEIL_FLOAT(k) + exit_steps) * t_voxel;
    VEIL_PRECISE float t_stop = direct ? t_end : VEIL_FLOAT(k) * t_voxel;
    int n = direct ? VEIL_INT(VEIL_FLOORF(t_end / t_voxel)) + 1 : k;
    VEIL_PRECISE float D = 0.0f, t0 = 0.0f;
    float r0 = VEIL_RHO(x0, x1, x2);
    for (int s = 1; s <= n; ++s) {
        VEIL_PRECISE float t1 = VEIL_MINF(t_stop, VEIL_FLOAT(s) * t_voxel);
        VEIL_PRECISE float r1 = veil_rho_clamped(VEIL_CTX_ARG VEIL_FLOAT(x0) + e[0] * t1, VEIL_FLOAT(x1) + e[1] * t1,
                                                 VEIL_FLOAT(x2) + e[2] * t1);
        D += h * (len * (t1 - t0)) * (0.5f * (r0 + r1));
        t0 = t1;
        r0 = r1;
    }
    if (direct) return D;
    /* the crossing point on plane x_a + k sign(e_a), kept within k voxels of
     * X on the other axes (rounding could step past) and inside the grid */
    int lo[3], hi[3];
    float f[3];
    for (int b = 0; b < 3; ++b) {
        if (b == a) {
            lo[b] = x[b] + (e[b] > 0.0f ? k : -k);
            hi[b] = lo[b];
            f[b] = 0.0f;
            continue;
        }
        VEIL_PRECISE float q = VEIL_FLOAT(x[b]) + e[b] * t_stop;
        float qc = VEIL_MINF(VEIL_MAXF(q, VEIL_FLOAT(x[b] - k)), VEIL_FLOAT(x[b] + k));
        qc = VEIL_MINF(VEIL_MAXF(qc, 0.0f), VEIL_FLOAT(VEIL_DIMS(b) - 1));
        float fl = VEIL_FLOORF(qc);
        lo[b] = VEIL_INT(fl);
        f[b] = qc - fl;
        hi[b] = f[b] > 0.0f ? lo[b] + 1 : lo[b];
    }
    /* bilinear over the two axes other than a */
    int b1 = a == 0 ? 1 : 0, b2 = a == 2 ? 1 : 2;
    int i1[3], i2[3], i3[3];
    for (int c = 0; c < 3; ++c) {
        i1[c] = c == b1 ? hi[c] : lo[c];
        i2[c] = c == b2 ? hi[c] : lo[c];
        i3[c] = c == b1 || c == b2 ? hi[c] : lo[c];
    }
    /* A stencil whose voxels' paths end differently straddles a kink of D:
     * interpolating there errs by O(h) at every step along the kink and the
     * errors add up. Such voxels (O(n^2) of them) integrate to the end. */
    int end = veil_path_end(VEIL_CTX_ARG x0, x1, x2, type, l0, l1, l2);
    if (veil_path_end(VEIL_CTX_ARG lo[0], lo[1], lo[2], type, l0, l1, l2) != end ||
        veil_path_end(VEIL_CTX_ARG i1[0], i1[1], i1[2], type, l0, l1, l2) != end ||
        veil_path_end(VEIL_CTX_ARG i2[0], i2[1], i2[2], type, l0, l1, l2) != end ||
        veil_path_end(VEIL_CTX_ARG i3[0], i3[1], i3[2], type, l0, l1, l2) != end) {
        int total_steps = VEIL_INT(VEIL_FLOORF(t_end / t_voxel)) + 1;
        for (int s = n + 1; s <= total_steps; ++s) {
            VEIL_PRECISE float t1 = VEIL_MINF(t_end, VEIL_FLOAT(s) * t_voxel);
            VEIL_PRECISE float r1 = veil_rho_clamped(VEIL_CTX_ARG VEIL_FLOAT(x0) + e[0] * t1,
                                                     VEIL_FLOAT(x1) + e[1] * t1, VEIL_FLOAT(x2) + e[2] * t1);
            D += h * (len * (t1 - t0)) * (0.5f * (r0 + r1));
            t0 = t1;
            r0 = r1;
        }
        return D;
    }
    VEIL_PRECISE float d00 = VEIL_DIN(lo[0], lo[1], lo[2]);
    VEIL_PRECISE float d10 = VEIL_DIN(i1[0], i1[1], i1[2]);
    VEIL_PRECISE float d01 = VEIL_DIN(i2[0], i2[1], i2[2]);
    VEIL_PRECISE float d11 = VEIL_DIN(i3[0], i3[1], i3[2]);
    VEIL_PRECISE float dq = (d00 * (1.0f - f[b1]) + d10 * f[b1]) * (1.0f - f[b2]) + (d01 * (1.0f - f[b1]) + d11 * f[b1]) * f[b2];
    VEIL_PRECISE float total = dq + D;
    return total;
}

#endif
