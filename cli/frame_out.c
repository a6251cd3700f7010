#include "frame_out.h"

#include <stdio.h>

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
    for (int i = 0; i < VEIL_STAGE_COUNT; ++i)
        printf("%-10s %9.2f ms  (%s: %s)\n", veil_stage_name((veil_stage_id)i), st->stage[i].ms,
               veil_stage_status_name(st->stage[i].status), st->stage[i].why);
}
