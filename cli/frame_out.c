#include "frame_out.h"

#include <stdio.h>

#include "cli_util.h"

veil_result veil_cli_write_frame(const veil_image_set* im, const char* exr, const char* png, int aovs,
                                 const veil_exr_meta* meta, veil_error* err)
{
    veil_cli_outputs out = {0};
    const char* stage = veil_cli_stage(&out, exr, err);
    veil_result r = stage ? veil_image_set_write_exr_meta(im, stage, aovs, meta, err) : VEIL_ERR_IO;
    stage = r == VEIL_OK && png ? veil_cli_stage(&out, png, err) : NULL;
    if (r == VEIL_OK && png) r = stage ? veil_write_png(stage, im->width, im->height, im->rgba, 0.0f, err) : VEIL_ERR_IO;
    veil_result c = veil_cli_commit(&out, r == VEIL_OK, err);
    return r == VEIL_OK ? c : r;
}

void veil_cli_print_stages(const veil_render_stats* st)
{
    for (int i = 0; i < VEIL_STAGE_COUNT; ++i)
        printf("%-10s %9.2f ms  (%s: %s)\n", veil_stage_name((veil_stage_id)i), st->stage[i].ms,
               veil_stage_status_name(st->stage[i].status), st->stage[i].why);
}
