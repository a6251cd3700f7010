#include "stage.h"

const char* veil_stage_name(veil_stage_id id)
{
    static const char* const names[VEIL_STAGE_COUNT] = {"inject", "propagate", "volumetric", "render", "spread"};
    return id >= 0 && id < VEIL_STAGE_COUNT ? names[id] : "?";
}

const char* veil_stage_status_name(veil_stage_status s)
{
    switch (s) {
    case VEIL_STAGE_RAN: return "ran";
    case VEIL_STAGE_CACHED: return "cached";
    case VEIL_STAGE_SKIPPED: return "skipped";
    }
    return "?";
}
