/* veil — the one shape of a pipeline stage: a key computed from
 * descriptions (never by reading the data it stands for), a build, and a
 * report. A stage runs when no result with its key is kept, is cached when
 * one is, and is skipped when the frame does not need it; the report says
 * which, why, and how long it took. `veil render --stats` prints the
 * reports of a frame, `--explain` the plan without rendering. The stages
 * themselves are the rows of frame/stages.h's table, in this order.
 */
#ifndef VEIL_STAGE_H
#define VEIL_STAGE_H

#include <stdint.h>

typedef enum veil_stage_id {
    VEIL_STAGE_INJECT = 0, /* sources -> extinction volume (volume/) */
    VEIL_STAGE_PROPAGATE,  /* EV -> optical-depth volumes (propagate/) */
    VEIL_STAGE_VOLUMETRIC, /* EV (+ OPVs) -> a view-independent multiple-scattering field (volumetric/volumetric.h) */
    VEIL_STAGE_RENDER,     /* the march: camera rays -> image set (render/) */
    VEIL_STAGE_SPREAD,     /* screen-space multiple scattering (render/spread.h) */
    VEIL_STAGE_COUNT
} veil_stage_id;

typedef enum veil_stage_status {
    VEIL_STAGE_RAN = 0,
    VEIL_STAGE_CACHED,
    VEIL_STAGE_SKIPPED
} veil_stage_status;

#define VEIL_STAGE_WHY_MAX 512

typedef struct veil_stage_report {
    veil_stage_status status;
    uint64_t key;                  /* 0 when skipped */
    double ms;                     /* wall time, GPU work finished */
    double gpu_ms;                 /* of it, the GPU's work (a GL timer query); < 0: not measured */
    char why[VEIL_STAGE_WHY_MAX];  /* why it ran, was cached or skipped, and what it did */
} veil_stage_report;

const char* veil_stage_name(veil_stage_id id);            /* "inject", "propagate", "volumetric", "render", "spread" */
const char* veil_stage_status_name(veil_stage_status s);  /* "ran", "cached", "skipped" */

#endif
