#define _POSIX_C_SOURCE 200809L
#include "vdb_volume.h"

#include "../scene/limits.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* At most this many threads for the box filter (one per core). */
#define VDB_MAX_THREADS 64
/* k is rounded up from a ratio computed in floating point: a ratio within
 * this much above a whole number of half-voxels counts as that number, so
 * that a 2x target gets k = 4, not 5. */
#define VDB_K_ROUNDING 1e-3

typedef struct vdb_geometry {
    double m[4][4]; /* index -> world, column vectors */
    int lo[3], hi[3];
    size_t active;
} vdb_geometry;

static veil_result geometry(const veil_vdb* v, vdb_geometry* geo, veil_error* err)
{
    veil_result r = veil_vdb_transform(v, geo->m, err);
    if (r != VEIL_OK) return r;
    r = veil_vdb_index_bbox(v, geo->lo, geo->hi, &geo->active);
    if (r != VEIL_OK)
        return veil_fail(err, r, "%s: grid '%s': cannot compute its bounding box", veil_vdb_path(v),
                         veil_vdb_grid_name(v));
    return VEIL_OK;
}

/* World AABB of the index box [lo - grow, hi + grow]. */
static void world_box(const vdb_geometry* geo, int grow, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; ++a) {
        lo[a] = HUGE_VAL;
        hi[a] = -HUGE_VAL;
    }
    for (int c = 0; c < 8; ++c) {
        double p[3];
        for (int a = 0; a < 3; ++a) p[a] = (c >> a) & 1 ? (double)geo->hi[a] + grow : (double)geo->lo[a] - grow;
        for (int r = 0; r < 3; ++r) {
            double w = geo->m[r][0] * p[0] + geo->m[r][1] * p[1] + geo->m[r][2] * p[2] + geo->m[r][3];
            lo[r] = fmin(lo[r], w);
            hi[r] = fmax(hi[r], w);
        }
    }
}

static veil_result bounds(const veil_vdb* v, int grow, float lo[3], float hi[3], veil_error* err)
{
    vdb_geometry geo;
    veil_result r = geometry(v, &geo, err);
    if (r != VEIL_OK) return r;
    if (geo.active == 0)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: grid '%s' has no active voxels, so it has no bounds",
                         veil_vdb_path(v), veil_vdb_grid_name(v));
    double dlo[3], dhi[3];
    world_box(&geo, grow, dlo, dhi);
    for (int a = 0; a < 3; ++a) {
        lo[a] = (float)dlo[a];
        hi[a] = (float)dhi[a];
    }
    return VEIL_OK;
}

veil_result veil_vdb_world_bounds(const veil_vdb* v, float lo[3], float hi[3], veil_error* err)
{
    return bounds(v, 0, lo, hi, err);
}

veil_result veil_vdb_world_support(const veil_vdb* v, float lo[3], float hi[3], veil_error* err)
{
    return bounds(v, 1, lo, hi, err);
}

/* The exact copy applies: m is s*I plus a translation with s = g->voxel,
 * and target centre i sits on index point first[a] + i on each axis. */
static int aligned(const vdb_geometry* geo, const veil_grid* g, int first[3])
{
    const double s = geo->m[0][0];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            if (r == c ? geo->m[r][c] != s : geo->m[r][c] != 0.0) return 0;
    if (!(s > 0.0) || fabs((double)g->voxel - s) > VEIL_VDB_ALIGN_TOL * s) return 0;
    for (int a = 0; a < 3; ++a) {
        /* index coordinate of the first and last target centres */
        double x0 = ((double)g->origin[a] + 0.5 * g->voxel - geo->m[a][3]) / s;
        double x1 = ((double)g->origin[a] + ((double)g->dims[a] - 0.5) * g->voxel - geo->m[a][3]) / s;
        double r0 = nearbyint(x0), r1 = nearbyint(x1);
        if (fabs(x0 - r0) > VEIL_VDB_ALIGN_TOL || fabs(x1 - r1) > VEIL_VDB_ALIGN_TOL) return 0;
        if (r1 - r0 != (double)g->dims[a] - 1.0) return 0;
        if (fabs(r0) > (double)(1 << 30)) return 0;
        first[a] = (int)r0;
    }
    return 1;
}

/* Inverse of the affine part (columns: index axes) and the translation. */
static int invert_affine(const double m[4][4], double inv[3][4])
{
    double c[3][3];
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
            c[k][r] = m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]; /* adjugate = cofactor transposed */
        }
    double det = m[0][0] * c[0][0] + m[0][1] * c[1][0] + m[0][2] * c[2][0];
    if (!(fabs(det) > 0.0) || !isfinite(det)) return 0;
    for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k) inv[r][k] = c[r][k] / det;
        inv[r][3] = -(inv[r][0] * m[0][3] + inv[r][1] * m[1][3] + inv[r][2] * m[2][3]);
    }
    return 1;
}

static veil_result check_grid(const veil_grid* g, veil_error* err)
{
    for (int a = 0; a < 3; ++a)
        if (g->dims[a] < 1 || !isfinite(g->origin[a]))
            return veil_fail(err, VEIL_ERR_INVALID, "resampling a VDB grid: the target grid is not valid");
    if (!(g->voxel > 0.0f) || !isfinite(g->voxel))
        return veil_fail(err, VEIL_ERR_INVALID, "resampling a VDB grid: the target voxel must be > 0, got %g",
                         (double)g->voxel);
    return VEIL_OK;
}

static size_t range_count(const int lo[3], const int hi[3])
{
    size_t n = 1;
    for (int a = 0; a < 3; ++a) n *= hi[a] < lo[a] ? 0 : (size_t)(hi[a] - lo[a] + 1);
    return n;
}

veil_result veil_vdb_plan_resample(const veil_vdb* v, const veil_grid* g, veil_vdb_resample_plan* plan,
                                   veil_error* err)
{
    memset(plan, 0, sizeof *plan);
    for (int a = 0; a < 3; ++a) plan->hi[a] = plan->dense_hi[a] = -1;
    veil_result r = check_grid(g, err);
    if (r != VEIL_OK) return r;
    vdb_geometry geo;
    if ((r = geometry(v, &geo, err)) != VEIL_OK) return r;
    if (geo.active == 0) return VEIL_OK; /* nothing to add */

    int first[3];
    if (aligned(&geo, g, first)) {
        plan->exact_copy = 1;
        plan->k = 1;
        for (int a = 0; a < 3; ++a) { /* target voxels whose index point lies in the active box */
            long long lo = (long long)geo.lo[a] - first[a], hi = (long long)geo.hi[a] - first[a];
            plan->lo[a] = lo < 0 ? 0 : lo > g->dims[a] ? g->dims[a] : (int)lo;
            plan->hi[a] = hi > g->dims[a] - 1 ? g->dims[a] - 1 : hi < -1 ? -1 : (int)hi;
        }
        plan->samples = range_count(plan->lo, plan->hi);
        return VEIL_OK;
    }

    /* Target voxels whose cube meets the field's support. */
    double slo[3], shi[3];
    world_box(&geo, 1, slo, shi);
    for (int a = 0; a < 3; ++a) {
        double lo = floor((slo[a] - g->origin[a]) / g->voxel), hi = ceil((shi[a] - g->origin[a]) / g->voxel) - 1.0;
        plan->lo[a] = lo < 0.0 ? 0 : lo > g->dims[a] ? g->dims[a] : (int)lo;
        plan->hi[a] = hi > g->dims[a] - 1 ? g->dims[a] - 1 : hi < -1.0 ? -1 : (int)hi;
    }
    size_t voxels = range_count(plan->lo, plan->hi);
    if (voxels == 0) return VEIL_OK;

    /* k from the ratio of the target voxel to the VDB's smallest voxel edge. */
    double h = HUGE_VAL;
    for (int c = 0; c < 3; ++c)
        h = fmin(h, sqrt(geo.m[0][c] * geo.m[0][c] + geo.m[1][c] * geo.m[1][c] + geo.m[2][c] * geo.m[2][c]));
    if (!(h > 0.0) || !isfinite(h))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: grid '%s': the transform's voxel size is %g", veil_vdb_path(v),
                         veil_vdb_grid_name(v), h);
    /* Reducing (target voxel larger than the VDB's): the box filter. Not reducing
     * (the same size under a rotation, or enlarging): the field at each target
     * centre, k = 1, the trilinear field itself (a box mean there would only
     * blur; tests/volume/test_vdb_import.c "filters" measures both). */
    double want = (double)g->voxel <= h * (1.0 + VDB_K_ROUNDING)
                      ? 1.0
                      : ceil(VEIL_VDB_SAMPLES_PER_VOXEL * (double)g->voxel / h - VDB_K_ROUNDING);
    int k = want < 1.0 ? 1 : want > VEIL_VDB_MAX_SUPERSAMPLE ? VEIL_VDB_MAX_SUPERSAMPLE : (int)want;
    size_t samples = 0;
    for (; k >= 1; --k)
        if (veil_mul_sizes(voxels, (size_t)k, (size_t)k, (size_t)k, &samples) && samples <= VEIL_VDB_MAX_SAMPLES)
            break;
    if (k < 1)
        return veil_fail(err, VEIL_ERR_LIMIT,
                         "%s: grid '%s' (active index box %dx%dx%d) covers %dx%dx%d = %zu voxels of the %dx%dx%d "
                         "extinction volume; resampling needs at least one sample per voxel, over the limit of %zu "
                         "samples: lower medium.max_resolution",
                         veil_vdb_path(v), veil_vdb_grid_name(v), geo.hi[0] - geo.lo[0] + 1,
                         geo.hi[1] - geo.lo[1] + 1, geo.hi[2] - geo.lo[2] + 1, plan->hi[0] - plan->lo[0] + 1,
                         plan->hi[1] - plan->lo[1] + 1, plan->hi[2] - plan->lo[2] + 1, voxels, g->dims[0],
                         g->dims[1], g->dims[2], VEIL_VDB_MAX_SAMPLES);
    plan->k = k;
    plan->samples = samples;

    /* The VDB values the samples reach: the index AABB of the touched
     * target voxels' world box, two points of margin (both corners of every
     * sample, and rounding), clipped to the active box grown by one (beyond
     * it the values are 0 and the sampler returns 0 itself). */
    double inv[3][4], wlo[3], whi[3];
    if (!invert_affine(geo.m, inv))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: grid '%s': its transform is singular", veil_vdb_path(v),
                         veil_vdb_grid_name(v));
    for (int a = 0; a < 3; ++a) {
        wlo[a] = g->origin[a] + (double)plan->lo[a] * g->voxel;
        whi[a] = g->origin[a] + ((double)plan->hi[a] + 1.0) * g->voxel;
    }
    for (int a = 0; a < 3; ++a) {
        double qlo = HUGE_VAL, qhi = -HUGE_VAL;
        for (int c = 0; c < 8; ++c) {
            double q = inv[a][3];
            for (int b = 0; b < 3; ++b) q += inv[a][b] * ((c >> b) & 1 ? whi[b] : wlo[b]);
            qlo = fmin(qlo, q);
            qhi = fmax(qhi, q);
        }
        double lo = fmax(floor(qlo) - 1.0, (double)geo.lo[a] - 1.0), hi = fmin(floor(qhi) + 2.0, (double)geo.hi[a] + 1.0);
        if (hi < lo) hi = lo; /* cannot happen for touched voxels; keeps the box valid */
        plan->dense_lo[a] = (int)lo;
        plan->dense_hi[a] = (int)hi;
    }
    size_t dn[3];
    for (int a = 0; a < 3; ++a) dn[a] = (size_t)((long long)plan->dense_hi[a] - plan->dense_lo[a] + 1);
    if (!veil_mul_sizes(dn[0], dn[1], dn[2], 1, &plan->dense_voxels) || plan->dense_voxels > VEIL_VDB_MAX_DENSE_VOXELS)
        return veil_fail(err, VEIL_ERR_LIMIT,
                         "%s: grid '%s': resampling reads its values on the index box [%d, %d, %d] .. [%d, %d, %d], "
                         "%zux%zux%zu = %.4g voxels (%.3g GiB), over the limit of %zu voxels (%.3g GiB): crop the "
                         "grid or coarsen it first",
                         veil_vdb_path(v), veil_vdb_grid_name(v), plan->dense_lo[0], plan->dense_lo[1],
                         plan->dense_lo[2], plan->dense_hi[0], plan->dense_hi[1], plan->dense_hi[2], dn[0], dn[1],
                         dn[2], (double)dn[0] * (double)dn[1] * (double)dn[2],
                         (double)dn[0] * (double)dn[1] * (double)dn[2] * sizeof(float) / (1024.0 * 1024.0 * 1024.0),
                         (size_t)VEIL_VDB_MAX_DENSE_VOXELS,
                         (double)VEIL_VDB_MAX_DENSE_VOXELS * sizeof(float) / (1024.0 * 1024.0 * 1024.0));
    return VEIL_OK;
}

/* Values below 0 read as 0 (a density or an emission: scene/limits.h). */
static void clamp_negative(float* x, size_t n)
{
    for (size_t i = 0; i < n; ++i) x[i] = x[i] < 0.0f ? 0.0f : x[i];
}

static veil_result copy_values(const veil_vdb* v, float scale, int clamp, const veil_grid* g,
                               const veil_vdb_resample_plan* p, float* density, veil_error* err)
{
    vdb_geometry geo;
    veil_result r = geometry(v, &geo, err);
    int first[3];
    if (r != VEIL_OK || !aligned(&geo, g, first)) return r != VEIL_OK ? r : VEIL_ERR_INVALID;
    const size_t nx = (size_t)(p->hi[0] - p->lo[0] + 1), ny = (size_t)(p->hi[1] - p->lo[1] + 1);
    float* slab = malloc(nx * ny * sizeof *slab); /* nx, ny <= g->dims: fits */
    if (!slab) return veil_fail(err, VEIL_ERR_OOM, "out of memory copying a VDB grid (%zux%zu floats)", nx, ny);
    for (int k = p->lo[2]; k <= p->hi[2] && r == VEIL_OK; ++k) {
        const int lo[3] = {first[0] + p->lo[0], first[1] + p->lo[1], first[2] + k};
        const int hi[3] = {first[0] + p->hi[0], first[1] + p->hi[1], first[2] + k};
        r = veil_vdb_dense(v, lo, hi, slab);
        if (r != VEIL_OK) {
            r = veil_fail(err, r, "%s: grid '%s': reading its values failed", veil_vdb_path(v), veil_vdb_grid_name(v));
            break;
        }
        if (clamp) clamp_negative(slab, nx * ny);
        for (size_t j = 0; j < ny; ++j) {
            float* row = density + ((size_t)k * (size_t)g->dims[1] + (size_t)p->lo[1] + j) * (size_t)g->dims[0] +
                         (size_t)p->lo[0];
            for (size_t i = 0; i < nx; ++i) row[i] += scale * slab[j * nx + i];
        }
    }
    free(slab);
    return r;
}

/* The VDB's values on an index box, sampled trilinearly at world points. */
typedef struct dense_field {
    const float* val; /* x fastest */
    int lo[3], n[3];  /* the box's first index point and size */
    double inv[3][4]; /* world -> index */
} dense_field;

static float dense_sample(const dense_field* f, const double p[3])
{
    size_t at = 0, stride[3] = {1, (size_t)f->n[0], (size_t)f->n[0] * (size_t)f->n[1]};
    double w[3];
    for (int a = 0; a < 3; ++a) {
        double q = f->inv[a][0] * p[0] + f->inv[a][1] * p[1] + f->inv[a][2] * p[2] + f->inv[a][3];
        double fl = floor(q);
        /* both corners in the box (also false for NaN); the plan makes the
         * box hold every corner that can carry density */
        if (!(fl >= f->lo[a] && fl < (double)f->lo[a] + f->n[a] - 1)) return 0.0f;
        at += (size_t)((int)fl - f->lo[a]) * stride[a];
        w[a] = q - fl;
    }
    const float* c = f->val + at;
    const size_t sy = stride[1], sz = stride[2];
    double x00 = c[0] + w[0] * ((double)c[1] - c[0]), x10 = c[sy] + w[0] * ((double)c[sy + 1] - c[sy]);
    double x01 = c[sz] + w[0] * ((double)c[sz + 1] - c[sz]);
    double x11 = c[sz + sy] + w[0] * ((double)c[sz + sy + 1] - c[sz + sy]);
    double y0 = x00 + w[1] * (x10 - x00), y1 = x01 + w[1] * (x11 - x01);
    return (float)(y0 + w[2] * (y1 - y0));
}

typedef struct filter_job {
    const dense_field* f;
    const veil_grid* g;
    const veil_vdb_resample_plan* p;
    float scale;
    float* density;
    int first, step; /* this job's target slabs: z = lo + first, + step, ... */
} filter_job;

/* The box filter: each target voxel gets the mean of k^3 samples at the
 * centres of its k^3 sub-cells (see vdb_volume.h). */
static void* filter_slabs(void* arg)
{
    const filter_job* j = arg;
    const veil_grid* g = j->g;
    const int k = j->p->k;
    double sub[VEIL_VDB_MAX_SUPERSAMPLE]; /* sub-cell centres, in voxels */
    for (int s = 0; s < k; ++s) sub[s] = ((double)s + 0.5) / k;
    const double h = g->voxel, inv_count = 1.0 / ((double)k * k * k);
    for (int z = j->p->lo[2] + j->first; z <= j->p->hi[2]; z += j->step)
        for (int y = j->p->lo[1]; y <= j->p->hi[1]; ++y)
            for (int x = j->p->lo[0]; x <= j->p->hi[0]; ++x) {
                double sum = 0.0, q[3];
                for (int c = 0; c < k; ++c) {
                    q[2] = g->origin[2] + (z + sub[c]) * h;
                    for (int b = 0; b < k; ++b) {
                        q[1] = g->origin[1] + (y + sub[b]) * h;
                        for (int a = 0; a < k; ++a) {
                            q[0] = g->origin[0] + (x + sub[a]) * h;
                            sum += dense_sample(j->f, q);
                        }
                    }
                }
                size_t at = ((size_t)z * (size_t)g->dims[1] + (size_t)y) * (size_t)g->dims[0] + (size_t)x;
                j->density[at] += (float)(j->scale * (sum * inv_count));
            }
    return NULL;
}

static veil_result box_filter(const veil_vdb* v, float scale, int clamp, const veil_grid* g,
                              const veil_vdb_resample_plan* p, float* density, veil_error* err)
{
    vdb_geometry geo;
    veil_result r = geometry(v, &geo, err);
    if (r != VEIL_OK) return r;
    dense_field f;
    if (!invert_affine(geo.m, f.inv))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: grid '%s': its transform is singular", veil_vdb_path(v),
                         veil_vdb_grid_name(v));
    for (int a = 0; a < 3; ++a) {
        f.lo[a] = p->dense_lo[a];
        f.n[a] = p->dense_hi[a] - p->dense_lo[a] + 1;
    }
    float* val = malloc(p->dense_voxels * sizeof *val); /* <= VEIL_VDB_MAX_DENSE_VOXELS: checked by the plan */
    if (!val)
        return veil_fail(err, VEIL_ERR_OOM, "%s: grid '%s': out of memory for its %dx%dx%d values (%.3g GiB)",
                         veil_vdb_path(v), veil_vdb_grid_name(v), f.n[0], f.n[1], f.n[2],
                         (double)p->dense_voxels * sizeof *val / (1024.0 * 1024.0 * 1024.0));
    if ((r = veil_vdb_dense(v, p->dense_lo, p->dense_hi, val)) != VEIL_OK) {
        free(val);
        return veil_fail(err, r, "%s: grid '%s': reading its values failed", veil_vdb_path(v), veil_vdb_grid_name(v));
    }
    if (clamp) clamp_negative(val, p->dense_voxels);
    f.val = val;

    /* Target slabs interleaved over threads; each voxel is written by one
     * thread in a fixed order, so the result does not depend on them. */
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    int slabs = p->hi[2] - p->lo[2] + 1;
    int threads = cpus < 1 ? 1 : cpus > VDB_MAX_THREADS ? VDB_MAX_THREADS : (int)cpus;
    if (threads > slabs) threads = slabs;
    filter_job jobs[VDB_MAX_THREADS];
    pthread_t tid[VDB_MAX_THREADS];
    int started[VDB_MAX_THREADS] = {0};
    for (int t = 0; t < threads; ++t) {
        jobs[t] = (filter_job){&f, g, p, scale, density, t, threads};
        if (t > 0) started[t] = pthread_create(&tid[t], NULL, filter_slabs, &jobs[t]) == 0;
    }
    filter_slabs(&jobs[0]);
    for (int t = 1; t < threads; ++t) {
        if (started[t]) pthread_join(tid[t], NULL);
        else filter_slabs(&jobs[t]); /* no thread: do its share here */
    }
    free(val);
    return VEIL_OK;
}

static veil_result to_grid(const veil_vdb* v, float density_scale, int keep_negative, const veil_grid* g,
                           float* density, veil_error* err)
{
    if (!v || !g || !density) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_to_grid: missing argument");
    if (!isfinite(density_scale))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: density_scale must be a finite number", veil_vdb_path(v));
    veil_vdb_resample_plan plan;
    veil_result r = veil_vdb_plan_resample(v, g, &plan, err);
    if (r != VEIL_OK || plan.samples == 0) return r;
    veil_vdb_values values;
    veil_vdb_value_range(v, &values);
    const int clamp = !keep_negative && values.negative > 0; /* nothing to do for most grids */
    return plan.exact_copy ? copy_values(v, density_scale, clamp, g, &plan, density, err)
                           : box_filter(v, density_scale, clamp, g, &plan, density, err);
}

veil_result veil_vdb_to_grid(const veil_vdb* v, float density_scale, const veil_grid* g, float* density,
                             veil_error* err)
{
    return to_grid(v, density_scale, 0, g, density, err);
}

veil_result veil_vdb_to_grid_signed(const veil_vdb* v, float scale, const veil_grid* g, float* out, veil_error* err)
{
    return to_grid(v, scale, 1, g, out, err);
}

veil_result veil_vdb_check_values(const veil_vdb* v, veil_values_kind kind, double scale, double offset,
                                  veil_error* err)
{
    static const struct {
        const char* one, *many, *what, *unit;
        double bound;
    } K[] = {
        {"is too large", "are too large", "value x density_scale", "", VEIL_MAX_DENSITY},
        {"emits too much", "emit too much", "value x emission.scale x color", " W m^-3 sr^-1", VEIL_MAX_EMISSION},
        {"is too hot", "are too hot", "temperature.scale x value + offset", " K", VEIL_MAX_KELVIN},
    };
    veil_vdb_values x;
    veil_vdb_value_range(v, &x);
    if (kind != VEIL_VALUES_TEMPERATURE) { /* below 0 reads 0 */
        x.min = x.min < 0.0 ? 0.0 : x.min;
        offset = 0.0;
    }
    /* the largest value the grid makes, and the raw values beyond the bound */
    /* the bound as a float holds it (the scene's scales are floats: 1e21 is 1.00000002e21) */
    const double hi = fmax(scale * x.min + offset, scale * x.max + offset), bound = (double)(float)K[kind].bound;
    if (!(hi > bound)) return VEIL_OK;
    const double edge = (bound - offset) / scale; /* scale != 0 here: else hi = offset <= bound */
    uint64_t n = scale > 0.0 ? veil_vdb_count_outside(v, -HUGE_VAL, edge) : veil_vdb_count_outside(v, edge, HUGE_VAL);
    return veil_fail(err, VEIL_ERR_INVALID,
                     "%s: grid '%s': %llu voxel%s %s: %s up to %.3g%s, over the bound of %.3g%s (scene/limits.h)",
                     veil_vdb_path(v), veil_vdb_grid_name(v), (unsigned long long)n, n == 1 ? "" : "s",
                     n == 1 ? K[kind].one : K[kind].many, K[kind].what, hi, K[kind].unit, bound, K[kind].unit);
}

int veil_vdb_lattice(const veil_vdb* v, double* edge, double origin[3], int* axis_aligned)
{
    vdb_geometry geo;
    veil_error ignored = {{0}};
    if (geometry(v, &geo, &ignored) != VEIL_OK || geo.active == 0) return 0;
    /* the world length of one index step along each index axis (a column's norm) */
    double smallest = HUGE_VAL;
    for (int c = 0; c < 3; ++c) {
        double n = sqrt(geo.m[0][c] * geo.m[0][c] + geo.m[1][c] * geo.m[1][c] + geo.m[2][c] * geo.m[2][c]);
        smallest = fmin(smallest, n);
    }
    if (!(smallest > 0.0) || !isfinite(smallest)) return 0;
    *edge = smallest;
    const double s = geo.m[0][0];
    int aligned_axes = s > 0.0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) aligned_axes &= r == c ? geo.m[r][c] == s : geo.m[r][c] == 0.0;
    *axis_aligned = aligned_axes;
    for (int a = 0; a < 3; ++a) origin[a] = geo.m[a][3];
    return 1;
}
