/* veil rbf generate: a seeded random particle file. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"
#include "scene/limits.h"
#include "commands.h"
#include "io/particles.h"
#include "scene/scene.h"

/* veil rbf generate: a seeded random particle file, optionally fBm-modulated. */
int veil_cmd_rbf(int argc, char** argv)
{
    if (argc < 3 || strcmp(argv[2], "generate") != 0)
        return veil_cli_usage_error("rbf: expected the subcommand 'generate', got '%s'", argc < 3 ? "" : argv[2]);
    const char* out = NULL;
    long count = -1, seed = -1, octaves = 4, format = -1; /* format: -1 by extension, 0 json, 1 binary */
    float v6[6] = {0}, bounds[6] = {0}, radius[2] = {0}, amp[2] = {0}, scale = 1.0f, amount = 0.0f;
    int have_b = 0, have_r = 0, have_a = 0;
    for (int i = 3; i < argc; ++i) {
        const char* s = argv[i];
        const char* v = i + 1 < argc ? argv[i + 1] : NULL;
        int nlist = !strcmp(s, "--bounds") ? 6 : (!strcmp(s, "--radius") || !strcmp(s, "--amplitude")) ? 2 : 0;
        int takes = nlist || !strcmp(s, "-o") || !strcmp(s, "--count") || !strcmp(s, "--seed") ||
                    !strcmp(s, "--noise-scale") || !strcmp(s, "--noise-octaves") || !strcmp(s, "--noise-amount") ||
                    !strcmp(s, "--format");
        if (!takes) {
            if (s[0] == '-' && s[1]) return veil_cli_usage_error("unknown option '%s'", s);
            return veil_cli_usage_error("unexpected argument '%s'", s);
        }
        if (!v) return veil_cli_usage_error("%s needs a value", s);
        ++i;
        if (nlist) { /* comma-separated finite numbers */
            const char* p = v;
            int k = 0;
            for (; k < nlist; ++k) {
                char* end;
                errno = 0;
                v6[k] = strtof(p, &end);
                if (errno || end == p || !isfinite(v6[k])) break;
                if (k + 1 < nlist && *end != ',') break;
                if (k + 1 == nlist && *end) break;
                p = end + 1;
            }
            int ok = k == nlist;
            if (ok && nlist == 6) {
                for (int a = 0; a < 3; ++a) ok = ok && v6[a] <= v6[a + 3];
                if (!ok)
                    return veil_cli_usage_error("--bounds: expected x0,y0,z0,x1,y1,z1 (min and max corner, m) with min <= max, got '%s'", v);
                for (int a = 0; a < 6; ++a) ok = ok && fabsf(v6[a]) <= (float)VEIL_MAX_COORD;
                if (!ok) /* the particles' centres are refused beyond it (scene/limits.h): say so before any is made */
                    return veil_cli_usage_error("--bounds: expected corners within [-1e15, 1e15] m (scene/limits.h), got '%s'", v);
                memcpy(bounds, v6, sizeof bounds), have_b = 1;
            } else if (ok && !strcmp(s, "--radius")) {
                if (!(v6[0] > 0 && v6[0] <= v6[1] && isfinite(1.0f / v6[0])))
                    return veil_cli_usage_error("--radius: expected r0,r1 with 0 < r0 <= r1 (m), got '%s'", v);
                memcpy(radius, v6, sizeof radius), have_r = 1;
            } else if (ok) {
                if (!(v6[0] >= 0 && v6[0] <= v6[1]))
                    return veil_cli_usage_error("--amplitude: expected c0,c1 with 0 <= c0 <= c1, got '%s'", v);
                if (!(v6[1] <= (float)VEIL_MAX_DENSITY))
                    return veil_cli_usage_error("--amplitude: expected c1 <= 1e10 (a density: scene/limits.h), got '%s'", v);
                memcpy(amp, v6, sizeof amp), have_a = 1;
            } else if (nlist == 6) {
                return veil_cli_usage_error("--bounds: expected 6 comma-separated numbers x0,y0,z0,x1,y1,z1, got '%s'", v);
            } else {
                return veil_cli_usage_error(!strcmp(s, "--radius") ? "--radius: expected 2 comma-separated numbers r0,r1, got '%s'"
                                                          : "--amplitude: expected 2 comma-separated numbers c0,c1, got '%s'", v);
            }
        } else if (!strcmp(s, "-o")) out = v;
        else if (!strcmp(s, "--count")) {
            if (!veil_cli_parse_int(v, 0, VEIL_SCENE_MAX_PARTICLES, &count)) return veil_cli_usage_error("--count: expected an integer in 0..10000000, got '%s'", v);
        } else if (!strcmp(s, "--seed")) {
            if (!veil_cli_parse_int(v, 0, 9007199254740991L, &seed)) return veil_cli_usage_error("--seed: expected an integer in 0..2^53-1, got '%s'", v);
        } else if (!strcmp(s, "--noise-octaves")) {
            if (!veil_cli_parse_int(v, 1, 16, &octaves)) return veil_cli_usage_error("--noise-octaves: expected an integer in 1..16, got '%s'", v);
        } else if (!strcmp(s, "--noise-amount")) {
            if (!veil_cli_parse_float(v, 0.0f, 1.0f, &amount)) return veil_cli_usage_error("--noise-amount: expected a number in 0..1, got '%s'", v);
        } else if (!strcmp(s, "--noise-scale")) {
            if (!veil_cli_parse_float(v, 1e-30f, 3.4e38f, &scale)) return veil_cli_usage_error("--noise-scale: expected a length > 0 (m), got '%s'", v);
        } else if (!strcmp(v, "json") || !strcmp(v, "binary")) format = !strcmp(v, "binary");
        else return veil_cli_usage_error("--format: expected json or binary, got '%s'", v);
    }
    if (!out) return veil_cli_usage_error("%s", "rbf generate: missing -o OUT");
    if (count < 0) return veil_cli_usage_error("%s", "rbf generate: missing --count N");
    if (seed < 0) return veil_cli_usage_error("%s", "rbf generate: missing --seed S");
    if (!have_b) return veil_cli_usage_error("%s", "rbf generate: missing --bounds x0,y0,z0,x1,y1,z1");
    if (!have_r) return veil_cli_usage_error("%s", "rbf generate: missing --radius r0,r1");
    if (!have_a) return veil_cli_usage_error("%s", "rbf generate: missing --amplitude c0,c1");
    if (format < 0) {
        size_t n = strlen(out);
        format = !(n >= 5 && !strcmp(out + n - 5, ".json"));
    }
    /* -o: a file of its own (not a directory, a FIFO), its folder made (cli/run_files.h) */
    const veil_run_file file = {.what = "-o", .path = out, .writes = 1};
    int rc = veil_cli_check_run(&file, 1, NULL);
    if (rc != EXIT_OK) return rc;
    veil_error err = {0};
    veil_cli_folders made = {0};
    veil_result r = veil_cli_make_folders(&file, 1, NULL, &made, &err);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    veil_rbf_random_desc d = {.count = (uint32_t)count, .seed = (uint64_t)seed,
                              .bounds = {{bounds[0], bounds[1], bounds[2]}, {bounds[3], bounds[4], bounds[5]}},
                              .radius = {radius[0], radius[1]}, .amplitude = {amp[0], amp[1]}};
    veil_particle* p = count ? malloc((size_t)count * sizeof *p) : NULL;
    if (count && !p) r = veil_fail(&err, VEIL_ERR_OOM, "out of memory for %ld particles", count);
    if (r == VEIL_OK) {
        veil_rbf_random_generate(&d, p);
        veil_particles_modulate(p, (size_t)count, (uint64_t)seed, scale, (int)octaves, amount);
        r = veil_particles_write(out, p, (size_t)count, (int)format, &err);
    }
    free(p);
    veil_cli_folders_done(&made, r == VEIL_OK);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    printf("wrote %s (%ld particles, %s)\n", out, count, format ? "binary" : "json");
    return EXIT_OK;
}

