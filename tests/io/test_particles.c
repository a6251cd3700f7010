/* veil tests — particle files (io/particles.h): JSON and binary round trips,
 * refusal of bad files with messages that name the file (and the particle
 * and field), the count limit, all-or-nothing writes, the scene's "file" key,
 * and a pinned hash of a seeded, noise-modulated binary file. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>

#include "support/check.h"
#include "io/particles.h"
#include "io/scene.h"
#include "support/temp_files.h"

static uint64_t fnv1a(const unsigned char* b, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

static void le32(unsigned char* b, uint32_t v)
{
    for (int k = 0; k < 4; ++k) b[k] = (unsigned char)(v >> (8 * k));
}

static void lef(unsigned char* b, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    le32(b, u);
}

/* A binary file by hand: header with `count`, then `n` records of v. */
static unsigned char* make_binary(uint32_t count, size_t n, const float (*v)[5], size_t* size)
{
    *size = 16 + 20 * n;
    unsigned char* b = calloc(1, *size);
    memcpy(b, "VEILRBF1", 8);
    le32(b + 8, count);
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 5; ++k) lef(b + 16 + 20 * i + 4 * k, v[i][k]);
    return b;
}

static int same_particles(const veil_particle* a, const veil_particle* b, size_t n)
{
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k)
            if (!same_bits(a[i].center[k], b[i].center[k])) return 0;
        if (!same_bits(a[i].amplitude, b[i].amplitude) || !same_bits(a[i].sharpness, b[i].sharpness)) return 0;
    }
    return 1;
}

/* Reads `path`, expecting failure with code (one of two) and every needle in the message. */
static void expect_fail(const char* path, veil_result c1, veil_result c2, const char* n1, const char* n2)
{
    veil_particle* p = (veil_particle*)1;
    size_t n = 99;
    veil_error err = {0};
    veil_result r = veil_particles_read(path, &p, &n, &err);
    CHECK(r == c1 || r == c2, "%s: got %s (%s)", path, veil_result_name(r), err.msg);
    CHECK(p == NULL && n == 0, "%s: outputs not cleared", path);
    CHECK(strstr(err.msg, path) != NULL, "message lacks the file name: %s", err.msg);
    if (n1) CHECK(strstr(err.msg, n1) != NULL, "message lacks '%s': %s", n1, err.msg);
    if (n2) CHECK(strstr(err.msg, n2) != NULL, "message lacks '%s': %s", n2, err.msg);
}

static void test_round_trips(void)
{
    enum { N = 2000 };
    veil_particle* p = malloc(N * sizeof *p);
    for (size_t i = 0; i < N; ++i) {
        for (int k = 0; k < 3; ++k) {
            float c = random_finite(); /* every mantissa, within scene/limits.h's 1e15 m */
            p[i].center[k] = fabsf(c) <= 1e15f ? c : c * (1e15f / 3.4028235e38f);
        }
        float a = fabsf(random_finite()); /* every mantissa, within scene/limits.h's 1e10 */
        p[i].amplitude = a <= 1e10f ? a : a * (1e10f / 3.4028235e38f);
        float s = fabsf(random_finite());
        p[i].sharpness = s >= 1e-29f ? s : 1.0f;
    }
    p[0].center[0] = -0.0f, p[1].amplitude = 0.0f, p[2].sharpness = 1e-29f, p[3].amplitude = 1e10f;
    /* the longest lines: every field at the largest magnitude it may have, 17 digits each */
    for (size_t i = 10; i < 1010; ++i) {
        for (int k = 0; k < 3; ++k) p[i].center[k] = -nextafterf(1e15f, 0.0f);
        p[i].amplitude = nextafterf(1e10f, 0.0f), p[i].sharpness = 3.4028235e38f;
    }
    for (int binary = 0; binary < 2; ++binary) {
        char path[256];
        path_in(path, sizeof path, binary ? "rt.bin" : "rt.json");
        veil_error err = {0};
        veil_result r = veil_particles_write(path, p, N, binary, &err);
        CHECK(r == VEIL_OK, "write %s: %s", path, err.msg);
        veil_particle* q = NULL;
        size_t n = 0;
        r = veil_particles_read(path, &q, &n, &err);
        CHECK(r == VEIL_OK && n == N, "read %s: %s (n=%zu)", path, err.msg, n);
        CHECK(r == VEIL_OK && same_particles(p, q, N), "%s: round trip is not bit-exact", path);
        if (binary) {
            size_t size = 0;
            unsigned char* b = slurp(path, &size);
            CHECK(size == 16 + 20 * (size_t)N, "binary size %zu", size);
            /* little-endian on disk, independent of the host: check one field by hand */
            uint32_t u;
            memcpy(&u, &p[5].sharpness, 4);
            const unsigned char* f = b + 16 + 20 * 5 + 16;
            CHECK(f[0] == (u & 255) && f[1] == ((u >> 8) & 255) && f[2] == ((u >> 16) & 255) && f[3] == (u >> 24),
                  "sharpness of particle 5 is not little-endian on disk");
            CHECK(b[8] == (N & 255) && b[9] == (N >> 8) && b[10] == 0 && b[11] == 0, "count not little-endian");
            free(b);
        }
        free(q);
        unlink(path);
    }
    /* a centre at -3.4e38: refused by name (it wrote past the JSON buffer: 172 bytes a line, 160 reserved) */
    for (int binary = 0; binary < 2; ++binary) {
        char path[256];
        path_in(path, sizeof path, binary ? "far.bin" : "far.json");
        veil_particle far = {{-3.4028235e38f, -3.4028235e38f, -3.4028235e38f}, 3.4028235e38f, 3.4028235e38f};
        veil_error err = {0};
        CHECK(veil_particles_write(path, &far, 1, binary, &err) == VEIL_ERR_INVALID &&
                  strstr(err.msg, "particle 0: center[0]") && strstr(err.msg, "[-1e15, 1e15]"),
              "a centre at -3.4e38: %s", err.msg);
        CHECK(access(path, F_OK) != 0, "%s written", path);
    }
    /* zero particles, both formats */
    for (int binary = 0; binary < 2; ++binary) {
        char path[256];
        path_in(path, sizeof path, binary ? "empty.bin" : "empty.json");
        veil_error err = {0};
        CHECK(veil_particles_write(path, NULL, 0, binary, &err) == VEIL_OK, "write empty: %s", err.msg);
        veil_particle* q = (veil_particle*)1;
        size_t n = 7;
        CHECK(veil_particles_read(path, &q, &n, &err) == VEIL_OK && n == 0 && q == NULL, "read empty: %s", err.msg);
        unlink(path);
    }
    free(p);
}

static void test_bad_binary(void)
{
    char path[256];
    path_in(path, sizeof path, "bad.bin");
    const float good[3][5] = {{0, 1, 2, 1, 5}, {1, 1, 1, 0.5f, 2}, {-1, 0, 0, 2, 3}};
    size_t size;
    unsigned char* b = make_binary(3, 3, good, &size);

    spit(path, b, size - 1); /* truncated by one byte */
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "truncated", "announces 3 particles");
    spit(path, b, 20); /* header and a bit */
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "truncated", "3 particles");
    spit(path, b, 10); /* not even a header */
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "truncated header", NULL);
    unsigned char* padded = calloc(1, size + 4);
    memcpy(padded, b, size);
    spit(path, padded, size + 4);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "trailing data", "expected exactly 76 bytes");
    free(padded);
    spit(path, "VEILRBF2\3\0\0\0\0\0\0\0", 16);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "not a particle file", NULL);
    spit(path, "\x89garbage\n", 9);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "not a particle file", NULL);
    spit(path, "", 0);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "empty file", NULL);
    b[12] = 1; /* reserved field */
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "reserved", NULL);
    b[12] = 0;

    lef(b + 16 + 20 * 2 + 16, -1.0f); /* particle 2: negative sharpness */
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "particle 2: sharpness", "expected a finite number >= 1e-29");
    lef(b + 16 + 20 * 2 + 16, 0.0f);
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "particle 2: sharpness", "got 0");
    /* scene/limits.h: a cut-off radius over 1e15 m (sharpness 1e-30) */
    lef(b + 16 + 20 * 2 + 16, 1e-30f);
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "particle 2: sharpness", "got 1e-30");
    lef(b + 16 + 20 * 2 + 16, 3.0f);
    lef(b + 16 + 20 * 1 + 4, NAN); /* particle 1: centre y NaN, said so without printing "nan" */
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "particle 1: center[1]", "got not a number");
    /* a centre at 3.4e38 is finite, but sums with it overflow (it crashed the splat): refused at load */
    lef(b + 16 + 20 * 1 + 4, 3.4028235e38f);
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "particle 1: center[1]", "[-1e15, 1e15]");
    lef(b + 16 + 20 * 1 + 4, -1.5e15f);
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "particle 1: center[1]", "got -1.5e+15");
    lef(b + 16 + 20 * 1 + 4, 1.0f);
    lef(b + 16 + 20 * 0 + 12, -0.5f); /* particle 0: negative amplitude */
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "particle 0: amplitude", "[0, 1e10]");
    /* an amplitude of 3e38 is finite, but 1e7 of them or one times sigma overflow (issue 22): refused */
    lef(b + 16 + 20 * 0 + 12, 3e38f);
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "particle 0: amplitude", "in [0, 1e10] (scene/limits.h), got 3e+38");
    lef(b + 16 + 20 * 0 + 12, INFINITY);
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_IO, "particle 0: amplitude", "got infinity");
    free(b);

    /* the count limit: refused from the header, before any allocation */
    b = make_binary(VEIL_SCENE_MAX_PARTICLES + 1, 0, NULL, &size);
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_LIMIT, VEIL_ERR_INVALID, "10000001 particles", "at most 10000000");
    free(b);
    b = make_binary(0xFFFFFFFFu, 0, NULL, &size);
    spit(path, b, size);
    expect_fail(path, VEIL_ERR_LIMIT, VEIL_ERR_INVALID, "4294967295 particles", NULL);
    free(b);
    unlink(path);

    char missing[256];
    path_in(missing, sizeof missing, "no_such.bin");
    expect_fail(missing, VEIL_ERR_IO, VEIL_ERR_IO, "cannot open", NULL);
}

static void test_bad_json(void)
{
    char path[256];
    path_in(path, sizeof path, "bad.json");
    static const struct { const char* text; const char* n1; const char* n2; } cases[] = {
        {"{\"format\":\"veil-particles\",\"version\":1,\"particles\":[{\"center\":[0,0,0],\"amplitude\":1,\"sharpness\":2},"
         "{\"center\":[0,0,0],\"amplitude\":1,\"sharpness\":-2}]}", "particles[1].sharpness", "expected a number >= 1e-29"},
        {"{\"format\":\"veil-particles\",\"version\":1,\"particles\":[{\"center\":[0,0,0],\"amplitude\":-1,\"sharpness\":2}]}",
         "particles[0].amplitude", "in [0, 1e10]"},
        {"{\"format\":\"veil-particles\",\"version\":1,\"particles\":[{\"center\":[0,0,0],\"amplitude\":3e38,\"sharpness\":2}]}",
         "particles[0].amplitude", "got 3e+38 (too large: at most 1e+10)"},
        {"{\"format\":\"veil-particles\",\"version\":1,\"particles\":[{\"center\":[0,1e39,0],\"amplitude\":1,\"sharpness\":2}]}",
         "particles[0].center", "single precision"},
        {"{\"format\":\"veil-particles\",\"version\":1,\"particles\":[{\"center\":[0,0],\"amplitude\":1,\"sharpness\":2}]}",
         "particles[0].center", NULL},
        {"{\"format\":\"veil-particles\",\"version\":1,\"particles\":[{\"center\":[0,0,0],\"amplitude\":1}]}",
         "particles[0].sharpness", "missing"},
        {"{\"format\":\"veil-particles\",\"version\":2,\"particles\":[]}", "version", "the number 1"},
        {"{\"format\":\"other\",\"version\":1,\"particles\":[]}", "format", "veil-particles"},
        {"{\"format\":\"veil-particles\",\"version\":1,\"particles\":[],\"extra\":0}", "extra", "unknown key"},
        {"  {\"format\":\"veil-particles\",\"version\":1,\"particles\":[}", "JSON syntax error", NULL},
        {"{\"format\":\"veil-particles\",\"version\":1,\"particles\":[]} x", "JSON syntax error", NULL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        spit(path, cases[i].text, strlen(cases[i].text));
        expect_fail(path, VEIL_ERR_INVALID, VEIL_ERR_PARSE, cases[i].n1, cases[i].n2);
    }
    unlink(path);
}

static void test_writes(void)
{
    veil_particle p[2] = {{{0, 0, 0}, 1, 2}, {{1, 2, 3}, 0.5f, 4}};
    veil_error err = {0};
    char path[256];
    /* into a missing folder: an error naming the file, nothing left anywhere */
    path_in(path, sizeof path, "no_such_folder/out.bin");
    for (int binary = 0; binary < 2; ++binary) {
        veil_result r = veil_particles_write(path, p, 2, binary, &err);
        CHECK(r == VEIL_ERR_IO && strstr(err.msg, "no_such_folder/out.bin"), "missing folder: %s", err.msg);
    }
    int temps = 0;
    CHECK(count_entries(g_dir, &temps) == 0, "files left after failed writes");
    /* invalid particles are refused before anything is written */
    path_in(path, sizeof path, "invalid.bin");
    p[1].sharpness = 0;
    CHECK(veil_particles_write(path, p, 2, 1, &err) == VEIL_ERR_INVALID && strstr(err.msg, "particle 1: sharpness"),
          "invalid particle written: %s", err.msg);
    CHECK(!file_exists(path), "a refused write left a file");
    p[1].sharpness = 4;
    /* over an existing file: replaced whole */
    CHECK(veil_particles_write(path, p, 2, 1, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_particles_write(path, p, 1, 1, &err) == VEIL_OK, "%s", err.msg);
    size_t size = 0;
    free(slurp(path, &size));
    CHECK(size == 36, "overwritten file has %zu bytes", size);
    /* a directory as the target is refused, and left alone */
    CHECK(veil_particles_write(g_dir, p, 1, 1, &err) == VEIL_ERR_IO, "writing over a folder: %s", err.msg);
    CHECK(count_entries(g_dir, &temps) == 1 && temps == 0, "temporaries left behind");
    unlink(path);
}

static void test_scene_file_key(void)
{
    veil_particle p[3] = {{{0, 0, 0}, 1, 2}, {{1, 2, 3}, 0.5f, 4}, {{-1, 0, 1}, 2, 8}};
    veil_error err = {0};
    char bin[256], scene[256];
    path_in(bin, sizeof bin, "cloud.bin");
    path_in(scene, sizeof scene, "scene.json");
    CHECK(veil_particles_write(bin, p, 3, 1, &err) == VEIL_OK, "%s", err.msg);
    const char* text = "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]},\n"
                       " \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": [{\"type\": \"rbf\", \"file\": \"cloud.bin\"}]}}";
    spit(scene, text, strlen(text));
    veil_scene s;
    veil_result r = veil_scene_load(scene, &s, &err);
    CHECK(r == VEIL_OK, "scene with a particle file: %s", err.msg);
    if (r == VEIL_OK) {
        CHECK(s.medium.sources[0].type == VEIL_SOURCE_RBF && s.medium.sources[0].particle_count == 3 &&
                  same_particles(s.medium.sources[0].particles, p, 3), "particles not loaded from the file");
        veil_particle* all = NULL;
        size_t n = 0;
        CHECK(veil_scene_particles(&s, &all, &n, &err) == VEIL_OK && n == 3, "veil_scene_particles: %s", err.msg);
        free(all);
        veil_scene_free(&s);
    }
    /* both keys, neither key, a corrupt file */
    const char* both = "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]},\n"
                       " \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": [{\"type\": \"rbf\", \"file\": \"cloud.bin\", \"particles\": []}]}}";
    spit(scene, both, strlen(both));
    r = veil_scene_load(scene, &s, &err);
    CHECK(r == VEIL_ERR_INVALID && strstr(err.msg, "medium.sources[0]: give either"), "both keys: %s", err.msg);
    const char* neither = "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]},\n"
                          " \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": [{\"type\": \"rbf\"}]}}";
    spit(scene, neither, strlen(neither));
    r = veil_scene_load(scene, &s, &err);
    CHECK(r == VEIL_ERR_INVALID && strstr(err.msg, "medium.sources[0]: missing required field"), "neither key: %s", err.msg);
    spit(scene, text, strlen(text));
    spit(bin, "VEILRBF1\1\0\0\0\0\0\0\0\0\0", 16);
    r = veil_scene_load(scene, &s, &err);
    CHECK(r == VEIL_ERR_INVALID && strstr(err.msg, "scene.json: medium.sources[0].file: ") &&
              strstr(err.msg, "cloud.bin: truncated"), "corrupt file: %s", err.msg);
    unlink(bin);
    r = veil_scene_load(scene, &s, &err);
    CHECK(r != VEIL_OK && strstr(err.msg, "medium.sources[0].file: cannot open") && strstr(err.msg, "cloud.bin"),
          "missing file: %s", err.msg);
    unlink(scene);
}

/* The CLI's recipe (veil rbf generate), through the library: pinned bytes. */
static void test_pinned_generation(void)
{
    veil_rbf_random_desc d = {.count = 1000, .seed = 42, .bounds = {{-1, -0.5f, -1}, {1, 0.5f, 1}},
                              .radius = {0.05f, 0.2f}, .amplitude = {0.5f, 2.0f}};
    veil_particle* p = malloc(d.count * sizeof *p);
    veil_rbf_random_generate(&d, p);
    veil_particles_modulate(p, d.count, d.seed, 0.5f, 4, 0.8f);
    float lo = 1, hi = 0;
    for (int i = 0; i < 2000; ++i) {
        float x[3] = {random_finite() * 1e-30f, (float)i * 0.37f - 300.0f, (float)(i % 17) * 0.11f};
        float n = veil_particles_fbm(7, 5, x);
        lo = n < lo ? n : lo, hi = n > hi ? n : hi;
    }
    CHECK(lo >= 0.0f && hi < 1.0f && hi - lo > 0.3f, "fbm range [%g, %g]", lo, hi);
    char a[256], b[256];
    path_in(a, sizeof a, "gen_a.bin");
    path_in(b, sizeof b, "gen_b.bin");
    veil_error err = {0};
    CHECK(veil_particles_write(a, p, d.count, 1, &err) == VEIL_OK, "%s", err.msg);
    veil_rbf_random_generate(&d, p);
    veil_particles_modulate(p, d.count, d.seed, 0.5f, 4, 0.8f);
    CHECK(veil_particles_write(b, p, d.count, 1, &err) == VEIL_OK, "%s", err.msg);
    size_t na = 0, nb = 0;
    unsigned char* ba = slurp(a, &na);
    unsigned char* bb = slurp(b, &nb);
    CHECK(na == nb && na == 16 + 20 * 1000 && memcmp(ba, bb, na) == 0, "two generations differ");
    uint64_t h = fnv1a(ba, na);
    printf("FNV-1a of the generated file: 0x%016llx\n", (unsigned long long)h);
    CHECK(h == 0x7a7b0541375a5832ull, "pinned hash changed: 0x%016llx", (unsigned long long)h);
    free(ba);
    free(bb);
    free(p);
    unlink(a);
    unlink(b);
}

int main(void)
{
    if (!test_dir_begin("particles")) return 1;
    test_round_trips();
    test_bad_binary();
    test_bad_json();
    test_writes();
    test_scene_file_key();
    test_pinned_generation();
    CHECK(test_dir_end(), "the test folder is not empty");
    return check_finish();
}
