/* libFuzzer target: the particle readers (io/particles.h), JSON or binary by
 * the input's first byte; what reads back must pass the writer's checks. */
#include "fuzz_common.h"
#include "io/particles.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const char* path = fuzz_file(data, size, size && (data[0] & 1) ? "p.bin" : "p.json");
    veil_particle* p = NULL;
    size_t n = 0;
    veil_error err = {0};
    if (veil_particles_read(path, &p, &n, &err) == VEIL_OK) {
        /* accepted particles are valid ones: writing them back must succeed */
        char out[160];
        snprintf(out, sizeof out, "%s.out", path);
        if (veil_particles_write(out, p, n, 0, &err) != VEIL_OK) abort();
        unlink(out);
    } else if (!err.msg[0]) {
        abort();
    }
    free(p);
    return 0;
}
