#include "motion_blur.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "vdb_volume.h"

int veil_motion_blur_samples(double d)
{
    if (!(d > VEIL_BLUR_MIN_SAMPLES)) return VEIL_BLUR_MIN_SAMPLES; /* NaN too */
    if (d >= VEIL_BLUR_MAX_SAMPLES) return VEIL_BLUR_MAX_SAMPLES;
    return (int)ceil(d);
}

void veil_motion_blur_times(const float shutter[2], int n, double* t)
{
    const double a = shutter[0], len = (double)shutter[1] - a;
    for (int k = 0; k < n; ++k) t[k] = a + len * ((double)k + 0.5) / n;
}

veil_result veil_motion_blur_open(const veil_scene* s, const veil_source* src, size_t i, const veil_vdb* density,
                                  veil_motion_blur* mb, veil_error* err)
{
    memset(mb, 0, sizeof *mb);
    const veil_vdb_source* vs = &src->vdb;
    if (!s->camera.has_shutter || !vs->has_velocity || src->type != VEIL_SOURCE_VDB) return VEIL_OK;
    veil_error inner = {{0}};
    veil_result r = veil_vdb_velocity_open(vs->file, vs->velocity_grid, &mb->velocity, mb->velocity_name,
                                           sizeof mb->velocity_name, &inner);
    if (r == VEIL_OK && vs->has_transform) r = veil_vdb_velocity_place(mb->velocity, vs->transform, &inner);
    if (r != VEIL_OK) {
        veil_motion_blur_close(mb);
        return veil_fail(err, r, "medium.sources[%zu].velocity%s: %.1900s", i, vs->velocity_grid ? ".grid" : "",
                         inner.msg);
    }
    const double fps = s->fps > 0.0 ? s->fps : VEIL_SCENE_DEFAULT_FPS;
    mb->per_frame = vs->velocity_scale / (vs->velocity_unit == VEIL_VELOCITY_PER_FRAME ? 1.0 : fps);
    double edge = 0.0, origin[3];
    int aligned;
    if (veil_vdb_lattice(density, &edge, origin, &aligned) && edge > 0.0)
        mb->displacement = veil_vdb_velocity_max(mb->velocity) * mb->per_frame *
                           ((double)s->camera.shutter[1] - s->camera.shutter[0]) / edge;
    mb->samples = veil_motion_blur_samples(mb->displacement);
    veil_motion_blur_times(s->camera.shutter, mb->samples, mb->times);
    return VEIL_OK;
}

veil_result veil_motion_blur_apply(const veil_motion_blur* mb, veil_vdb* g, int clamp_negative, double* seconds,
                                   veil_vdb_advect_report* report, veil_error* err)
{
    if (report) memset(report, 0, sizeof *report);
    if (!mb->velocity) return VEIL_OK;
    const veil_vdb_advect_desc d = {mb->times, mb->samples, mb->per_frame, VEIL_BLUR_STEP_VOXELS, clamp_negative};
    veil_vdb_advect_work w;
    veil_result r = veil_vdb_advect_work_of(g, mb->velocity, &d, &w, err);
    if (r != VEIL_OK) return r;
    const double cost = w.reads * VEIL_BLUR_READ_SECONDS, before = seconds ? *seconds : 0.0;
    if (w.at_least || before + cost > VEIL_BLUR_MAX_SECONDS)
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: grid '%s': motion blur by '%s' would move it up to %.3g voxels: "
                         "%s%.3g voxels around it, %.0f reads each (%d samples and the paths' steps): %.3g s of "
                         "CPU time%s, over the budget of %.0f s a frame (volume/motion_blur.h): check the velocity's "
                         "unit and scale (cm/s read as m/s is 100 times too fast), or shorten the shutter",
                         veil_vdb_path(g), veil_vdb_grid_name(g), mb->velocity_name, w.max_displacement_voxels,
                         w.at_least ? "over " : "", w.voxels, w.reads_per_voxel, mb->samples,
                         cost, before > 0.0 ? ", with the frame's blurs before it more" : "", VEIL_BLUR_MAX_SECONDS);
    if (seconds) *seconds = before + cost;
    return veil_vdb_advect_mean(g, mb->velocity, &d, report, err);
}

void veil_motion_blur_close(veil_motion_blur* mb)
{
    if (!mb) return;
    veil_vdb_velocity_close(mb->velocity);
    memset(mb, 0, sizeof *mb);
}
