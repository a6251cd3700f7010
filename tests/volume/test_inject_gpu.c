/* The GPU splat (volume/shaders/inject_rbf.comp) equals the CPU one
 * (veil_inject_rbf_cpu) on a small odd-sized grid.
 *
 * Both evaluate the same float operations in the same order; `precise`
 * keeps the GPU from fusing multiply-adds, so the cut-off test decides the
 * same way. They may differ only in exp(): GLSL 4.50 allows 3 + 2|x| ulp,
 * glibc's expf is within 1 ulp, and |x| <= -ln(VEIL_RBF_CUTOFF) = 9.21, so
 * each term differs by at most 22.4 + 1 ulp plus 1 ulp for the product
 * with the amplitude. A sum of n positive terms computed in the same order
 * then differs by at most (24.4 + n) ulp of the sum: relative
 * (25 + n) * 2^-23 (an ulp is at most 2^-23 of the value).
 *
 * The dispatches (issue 41): runs of bricks in their order, each under the
 * cap or one brick: with a cap of 2^22 evaluations the big splat's
 * dispatches each report at most the cap or its largest brick, at least
 * all / max(cap, brick) of them, and it still equals the CPU's; a cancel
 * asked for at the first report stops it there (VEIL_ERR_CANCELLED, no
 * report after). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "core/progress.h"
#include "frame/renderer.h"
#include "volume/ev.h"

/* Splats d's particles on a grid of `res` voxels a side both ways and
 * compares them voxel by voxel within the bound above. */
/* What the splat reported (core/progress.h). */
typedef struct splat_log {
    int calls, increasing, cancel_at, after;
    double first, last, total, step; /* step: the largest share one dispatch reported */
} splat_log;

static void on_progress(void* user, const char* what, double done, double total)
{
    splat_log* l = user;
    if (strcmp(what, "RBF splat") != 0) return;
    if (l->calls == 0) {
        l->first = done;
        l->increasing = 1;
    } else if (!(done > l->last)) {
        l->increasing = 0;
    }
    if (l->calls > 0 && done - l->last > l->step) l->step = done - l->last;
    if (l->cancel_at && l->calls >= l->cancel_at) ++l->after;
    l->last = done;
    l->total = total;
    if (++l->calls == l->cancel_at) veil_progress_cancel();
}

/* dispatches: how many the cap gives (as volume/inject_gpu.c splits), or -1: at least all / max(cap, the
 * largest brick) of them, each at most the cap or one brick */
static void compare(veil_renderer* r, const veil_rbf_random_desc* d, int res, size_t cap, int dispatches)
{
    veil_ev_set_splat_evals(cap);
    veil_error err = {0};
    veil_particle* p = malloc(d->count * sizeof *p);
    veil_rbf_random_generate(d, p);
    float lo[3], hi[3];
    veil_rbf_bounds(p, d->count, lo, hi);
    veil_grid g;
    veil_grid_fit(lo, hi, res, &g, &err);
    size_t nv = veil_grid_voxels(&g);
    float* cpu = calloc(nv, sizeof(float));
    float* gpu = malloc(nv * sizeof(float));
    veil_rbf_bins bins;
    CHECK(veil_rbf_bin(&g, p, d->count, &bins, &err) == VEIL_OK, "%s", err.msg);
    veil_inject_rbf_cpu(&g, &bins, cpu);
    splat_log log = {0};
    void* old_user = NULL;
    veil_progress_fn old = veil_progress_sink(on_progress, &log, &old_user);
    CHECK(veil_renderer_inject(r, &g, p, d->count, gpu, &err) == VEIL_OK, "%s", err.msg);
    veil_progress_sink(old, old_user, NULL);
    /* the splat reports 0 first, then after each dispatch the evaluations done, ending at all of them */
    const double all = (double)bins.list_len * 512;
    double row = 0.0; /* the largest brick's evaluations */
    const size_t bricks = (size_t)bins.bricks[0] * (size_t)bins.bricks[1] * (size_t)bins.bricks[2];
    for (size_t k = 0; k < bricks; ++k) row = fmax(row, (double)(bins.start[k + 1] - bins.start[k]) * 512);
    if (dispatches >= 0)
        CHECK(log.calls == 1 + dispatches, "splat progress: %d calls (expected %d)", log.calls, 1 + dispatches);
    else
        CHECK(log.calls - 1 >= (int)ceil(all / fmax((double)cap, row)) && log.step <= fmax((double)cap, row) &&
                  log.calls - 1 > 2,
              "runs: %d dispatches of at most %g (cap %g, a brick up to %g) for %g", log.calls - 1, log.step,
              (double)cap, row, all);
    CHECK(log.first == 0.0 && log.last == all && log.total == all && log.increasing,
          "splat progress: first %g, last %g of %g (expected %g), increasing %d", log.first, log.last, log.total,
          all, log.increasing);

    int bad = 0;
    double worst = 0.0, total = 0.0;
    for (int k = 0; k < g.dims[2]; ++k)
        for (int j = 0; j < g.dims[1]; ++j)
            for (int i = 0; i < g.dims[0]; ++i) {
                size_t v = ((size_t)k * g.dims[1] + j) * g.dims[0] + i;
                size_t brick = ((size_t)(k / VEIL_BRICK) * bins.bricks[1] + j / VEIL_BRICK) * bins.bricks[0] + i / VEIL_BRICK;
                double n = bins.start[brick + 1] - bins.start[brick];
                double tol = (25.0 + n) * 0x1p-23 * fabs(cpu[v]);
                double e = fabs((double)gpu[v] - cpu[v]);
                if (!(e <= tol)) ++bad;
                if (cpu[v] > 0) worst = fmax(worst, e / cpu[v]);
                total += cpu[v];
            }
    printf("%dx%dx%d voxels, %u particles, %.3g evaluations (%d dispatches of at most %.3g): largest relative "
           "GPU-CPU difference %.3g\n", g.dims[0], g.dims[1], g.dims[2], d->count, (double)bins.list_len * 512,
           log.calls - 1, (double)cap, worst);
    CHECK(total > 0.0, "empty volume");
    CHECK(bad == 0, "%d voxels differ beyond the exp() error bound", bad);
    veil_rbf_bins_free(&bins);
    free(cpu);
    free(gpu);
    free(p);
}

/* A cancel asked for at the splat's first report after a dispatch: VEIL_ERR_CANCELLED, nothing after. */
static void cancel_at_first(veil_renderer* r, const veil_rbf_random_desc* d, int res)
{
    veil_error err = {0};
    veil_particle* p = malloc(d->count * sizeof *p);
    veil_rbf_random_generate(d, p);
    float lo[3], hi[3];
    veil_rbf_bounds(p, d->count, lo, hi);
    veil_grid g;
    veil_grid_fit(lo, hi, res, &g, &err);
    float* gpu = malloc(veil_grid_voxels(&g) * sizeof(float));
    veil_ev_set_splat_evals((size_t)1 << 22);
    splat_log log = {.cancel_at = 2};
    void* old_user = NULL;
    veil_progress_fn old = veil_progress_sink(on_progress, &log, &old_user);
    veil_result res_ = veil_renderer_inject(r, &g, p, d->count, gpu, &err);
    veil_progress_sink(old, old_user, NULL);
    CHECK(res_ == VEIL_ERR_CANCELLED && log.after == 0 && strstr(err.msg, "during the RBF splat"),
          "cancel at the first dispatch: %d: %s, %d reports after", (int)res_, err.msg, log.after);
    free(gpu);
    free(p);
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer* r = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    veil_rbf_random_desc small = {.count = 400, .seed = 11, .bounds = {{0, 0, 0}, {1.3f, 1.0f, 0.8f}},
                                  .radius = {0.03f, 0.15f}, .amplitude = {0.2f, 3.0f}};
    compare(r, &small, 37, VEIL_SPLAT_DISPATCH_EVALS, 1);
    /* particles nearly as large as the grid: 3e8 evaluations, more than one dispatch of
     * VEIL_SPLAT_DISPATCH_EVALS (2.7e8): the layers of bricks each dispatch takes must still add up */
    veil_rbf_random_desc big = {.count = 1600, .seed = 5, .bounds = {{0, 0, 0}, {1, 1, 1}},
                                .radius = {0.6f, 0.8f}, .amplitude = {0.01f, 0.02f}};
    compare(r, &big, 64, VEIL_SPLAT_DISPATCH_EVALS, 2);
    /* the same in dispatches of 2^22 evaluations: about 70 of them */
    compare(r, &big, 64, (size_t)1 << 22, -1);
    cancel_at_first(r, &big, 64);
    veil_ev_set_splat_evals(0);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
