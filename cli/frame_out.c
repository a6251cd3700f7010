#define _POSIX_C_SOURCE 200809L
#include "frame_out.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"

#include "cli_util.h"

veil_result veil_cli_write_frame(const veil_image_set* im, const char* exr, const char* png, const char* deep,
                                 int aovs, const veil_exr_meta* meta, veil_error* err)
{
    veil_cli_outputs out = {0};
    const char* stage = veil_cli_stage(&out, exr, err);
    veil_result r = stage ? veil_image_set_write_exr_meta(im, stage, aovs, meta, err) : VEIL_ERR_IO;
    stage = r == VEIL_OK && png ? veil_cli_stage(&out, png, err) : NULL;
    if (r == VEIL_OK && png) r = stage ? veil_write_png(stage, im->width, im->height, im->rgba, 0.0f, err) : VEIL_ERR_IO;
    if (r == VEIL_OK && deep && !im->deep.counts)
        r = veil_fail(err, VEIL_ERR_INVALID, "%s: the frame was rendered without its deep image", deep);
    stage = r == VEIL_OK && deep ? veil_cli_stage(&out, deep, err) : NULL;
    if (r == VEIL_OK && deep) r = stage ? veil_write_deep_exr(stage, &im->deep, meta, err) : VEIL_ERR_IO;
    veil_result c = veil_cli_commit(&out, r == VEIL_OK, err);
    return r == VEIL_OK ? c : r;
}

void veil_cli_print_deep(const veil_deep_report* d)
{
    printf("deep       %9.2f ms  (%zu raw samples, at most %d a pixel, merged to %zu, at most %d a pixel; holdout "
           "error of the merge at the raw samples' depths: alpha max %.3g, mean %.3g; colour (of the pixel's) max %.3g, "
           "mean %.3g; flat light spread over the samples: at most %.3g)\n",
           d->ms, d->raw, d->max_raw, d->kept, d->cap, d->holdout_alpha_max, d->holdout_alpha_mean,
           d->holdout_color_max, d->holdout_color_mean, d->residual_max);
}

void veil_cli_print_stages(const veil_render_stats* st)
{
    for (int i = 0; i < VEIL_STAGE_COUNT; ++i) {
        const veil_stage_report* s = &st->stage[i];
        char gpu[64] = ""; /* the GPU's share, where a timer query measured it */
        if (s->status == VEIL_STAGE_RAN && s->gpu_ms >= 0.0) snprintf(gpu, sizeof gpu, "; GPU %.2f ms of it", s->gpu_ms);
        printf("%-10s %9.2f ms  (%s: %s%s)\n", veil_stage_name((veil_stage_id)i), s->ms,
               veil_stage_status_name(s->status), s->why, gpu);
    }
}

/* ---- the writer thread ---------------------------------------------------------------------------- */

typedef struct writer_job {
    veil_image_set im;
    long frame;
    char exr[4096], png[4096], deep[4096];
    int has_png, has_deep, aovs, has_meta;
    veil_exr_meta meta;
    char strings[VEIL_EXR_META_STRINGS][2][512]; /* meta's strings, copied */
} writer_job;

struct veil_cli_writer {
    pthread_t thread;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int busy, quit, stats;   /* busy: a job waits or is being written */
    writer_job job;
    veil_result r;           /* the first failure */
    veil_error err;
    double write_ms, waited_ms;
};

static void* writer_main(void* arg)
{
    veil_cli_writer* w = arg;
    pthread_mutex_lock(&w->mu);
    for (;;) {
        while (!w->busy && !w->quit) pthread_cond_wait(&w->cv, &w->mu);
        if (!w->busy) break; /* quit, nothing left */
        pthread_mutex_unlock(&w->mu);
        writer_job* j = &w->job;
        const double t0 = veil_now_ms();
        veil_error err = {0};
        veil_result r = veil_cli_write_frame(&j->im, j->exr, j->has_png ? j->png : NULL, j->has_deep ? j->deep : NULL,
                                             j->aovs, j->has_meta ? &j->meta : NULL, &err);
        const double ms = veil_now_ms() - t0;
        veil_image_set_free(&j->im);
        if (r == VEIL_OK && w->stats) {
            flockfile(stdout);
            printf("write      %9.2f ms  (frame %ld, its own thread)\n", ms, j->frame);
            funlockfile(stdout);
        }
        pthread_mutex_lock(&w->mu);
        w->write_ms += ms;
        if (r != VEIL_OK && w->r == VEIL_OK) w->r = r, w->err = err;
        w->busy = 0;
        pthread_cond_broadcast(&w->cv);
    }
    pthread_mutex_unlock(&w->mu);
    return NULL;
}

veil_result veil_cli_writer_start(int stats, veil_cli_writer** out, veil_error* err)
{
    *out = NULL;
    veil_cli_writer* w = calloc(1, sizeof *w);
    if (!w) return veil_fail(err, VEIL_ERR_OOM, "out of memory for the frame writer");
    w->stats = stats;
    pthread_mutex_init(&w->mu, NULL);
    pthread_cond_init(&w->cv, NULL);
    if (pthread_create(&w->thread, NULL, writer_main, w) != 0) {
        pthread_cond_destroy(&w->cv);
        pthread_mutex_destroy(&w->mu);
        free(w);
        return veil_fail(err, VEIL_ERR_OOM, "cannot start the frame writer's thread");
    }
    *out = w;
    return VEIL_OK;
}

/* Copies src (up to cap bytes with its NUL); 0 when it does not fit. */
static int copy_text(char* dst, size_t cap, const char* src)
{
    size_t n = strlen(src);
    if (n >= cap) return 0;
    memcpy(dst, src, n + 1);
    return 1;
}

veil_result veil_cli_writer_put(veil_cli_writer* w, veil_image_set* im, long frame, const char* exr, const char* png,
                                const char* deep, int aovs, const veil_exr_meta* meta, veil_error* err)
{
    const double t0 = veil_now_ms();
    pthread_mutex_lock(&w->mu);
    while (w->busy) pthread_cond_wait(&w->cv, &w->mu);
    w->waited_ms += veil_now_ms() - t0;
    veil_result r = w->r;
    if (r != VEIL_OK) *err = w->err;
    pthread_mutex_unlock(&w->mu);
    if (r != VEIL_OK) return r; /* an earlier frame failed: nothing after it is written */
    writer_job* j = &w->job; /* the writer is idle: the job is ours until busy is set */
    memset(j, 0, sizeof *j);
    j->frame = frame, j->aovs = aovs, j->has_png = png != NULL, j->has_deep = deep != NULL;
    int ok = copy_text(j->exr, sizeof j->exr, exr) && (!png || copy_text(j->png, sizeof j->png, png)) &&
             (!deep || copy_text(j->deep, sizeof j->deep, deep));
    if (meta) {
        j->has_meta = 1;
        j->meta = *meta;
        for (int i = 0; i < meta->n_strings && i < VEIL_EXR_META_STRINGS && ok; ++i)
            for (int k = 0; k < 2 && ok; ++k) {
                const char* t = meta->strings[i][k];
                ok = !t || copy_text(j->strings[i][k], sizeof j->strings[i][k], t);
                j->meta.strings[i][k] = t ? j->strings[i][k] : NULL;
            }
    }
    if (!ok) return veil_fail(err, VEIL_ERR_INVALID, "%s: a path or header attribute too long", exr);
    j->im = *im;
    memset(im, 0, sizeof *im);
    pthread_mutex_lock(&w->mu);
    w->busy = 1;
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
    return VEIL_OK;
}

veil_result veil_cli_hand_over(veil_cli_writer** w, int stats, const veil_render_stats* st, veil_image_set* im,
                               long frame, const char* exr, const char* png, const char* deep, int aovs,
                               const veil_exr_meta* meta, veil_error* err)
{
    if (stats) { /* before the hand-over: the writer prints its own line */
        flockfile(stdout);
        printf("frame %ld\n", frame);
        veil_cli_print_stages(st);
        if (deep) veil_cli_print_deep(&st->deep);
        funlockfile(stdout);
    }
    veil_result r = *w ? VEIL_OK : veil_cli_writer_start(stats, w, err);
    return r == VEIL_OK ? veil_cli_writer_put(*w, im, frame, exr, png, deep, aovs, meta, err) : r;
}

veil_result veil_cli_writer_finish(veil_cli_writer* w, double* write_ms, double* waited_ms, veil_error* err)
{
    if (!w) return VEIL_OK;
    const double t0 = veil_now_ms();
    pthread_mutex_lock(&w->mu);
    w->quit = 1;
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
    pthread_join(w->thread, NULL); /* it writes what it holds first */
    w->waited_ms += veil_now_ms() - t0;
    veil_result r = w->r;
    if (r != VEIL_OK && err) *err = w->err;
    if (write_ms) *write_ms = w->write_ms;
    if (waited_ms) *waited_ms = w->waited_ms;
    veil_image_set_free(&w->job.im);
    pthread_cond_destroy(&w->cv);
    pthread_mutex_destroy(&w->mu);
    free(w);
    return r;
}
