/* libFuzzer target: a VDB file read as a velocity (issue 41): opened (a vec3
 * grid, or a float triple NAME.x/.y/.z), placed by a transform, and the
 * motion blur it would drive counted (veil_vdb_advect_work_of) for a small
 * puff over a shutter; a blur under 2^20 reads is made, and the blurred
 * grid's values are finite and non-negative. Every refusal has a message. */
#include "fuzz_common.h"
#include "io/vdb.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const char* path = fuzz_file(data, size, "vel.vdb");
    veil_vdb_velocity* vel = NULL;
    char chosen[128];
    veil_error err = {0};
    if (veil_vdb_velocity_open(path, NULL, &vel, chosen, sizeof chosen, &err) != VEIL_OK) {
        if (!err.msg[0]) abort();
        return 0;
    }
    const double place[4][4] = {{0, 0.5, 0, 1}, {-0.5, 0, 0, 0}, {0, 0, 0.5, -2}, {0, 0, 0, 1}};
    veil_error e2 = {0};
    if (veil_vdb_velocity_place(vel, place, &e2) != VEIL_OK) {
        if (!e2.msg[0]) abort();
        veil_vdb_velocity_close(vel);
        return 0;
    }
    if (!(veil_vdb_velocity_max(vel) >= 0.0) || !isfinite(veil_vdb_velocity_max(vel))) abort();
    static float puff[6 * 6 * 6];
    for (int i = 0; i < 6 * 6 * 6; ++i) puff[i] = (float)((i * 7) % 5) * 0.25f;
    const int dims[3] = {6, 6, 6};
    const double m[4][4] = {{0.25, 0, 0, -0.5}, {0, 0.25, 0, 0.5}, {0, 0, 0.25, 0}, {0, 0, 0, 1}};
    veil_vdb* g = NULL;
    veil_error e3 = {0};
    if (veil_vdb_from_dense("puff", "density", puff, dims, 0, m, &g, &e3) != VEIL_OK) abort(); /* ours */
    const double times[4] = {-0.375, -0.125, 0.125, 0.375};
    const veil_vdb_advect_desc d = {times, 4, 1.0, 1.0, 1};
    veil_vdb_advect_work w;
    veil_error e4 = {0};
    veil_result r = veil_vdb_advect_work_of(g, vel, &d, &w, &e4);
    if (r != VEIL_OK && !e4.msg[0]) abort();
    if (r == VEIL_OK && !w.at_least && w.reads < (double)(1 << 20)) {
        veil_vdb_advect_report rep;
        veil_error e5 = {0};
        if (veil_vdb_advect_mean(g, vel, &d, &rep, &e5) == VEIL_OK) {
            veil_vdb_values x;
            veil_vdb_value_range(g, &x);
            if (!isfinite(x.min) || !isfinite(x.max) || x.min < 0.0) abort();
        } else if (!e5.msg[0]) {
            abort();
        }
    }
    veil_vdb_close(g);
    veil_vdb_velocity_close(vel);
    return 0;
}
