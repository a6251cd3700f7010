/* veil tests — files in a fresh temporary folder, and random floats, for
 * the image tests. Include after defining _POSIX_C_SOURCE. */
#ifndef VEIL_TEST_TEMP_FILES_H
#define VEIL_TEST_TEMP_FILES_H

#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char g_dir[64];

static inline void path_in(char* buf, size_t n, const char* name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
}

/* Entries of `dir` other than . and ..; *temps counts names with ".tmp". */
static inline int count_entries(const char* dir, int* temps)
{
    int n = 0;
    if (temps) *temps = 0;
    DIR* d = opendir(dir);
    if (!d) return -1;
    struct dirent* e;
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        ++n;
        if (temps && strstr(e->d_name, ".tmp")) ++*temps;
    }
    closedir(d);
    return n;
}

static inline int file_exists(const char* path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static inline unsigned char* slurp(const char* path, size_t* size)
{
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 16, n = 0;
    unsigned char* buf = malloc(cap);
    for (;;) {
        if (n == cap) {
            cap *= 2;
            unsigned char* b = realloc(buf, cap);
            if (!b) break;
            buf = b;
        }
        size_t r = fread(buf + n, 1, cap - n, f);
        if (r == 0) break;
        n += r;
    }
    fclose(f);
    *size = n;
    return buf;
}

static inline int spit(const char* path, const void* data, size_t size)
{
    FILE* f = fopen(path, "wb");
    if (!f) return 0;
    int ok = fwrite(data, 1, size, f) == size;
    return fclose(f) == 0 && ok;
}

static uint32_t g_rng = 12345u;
static inline uint32_t rng(void)
{
    g_rng = g_rng * 1664525u + 1013904223u;
    return g_rng;
}

/* A finite float from random bits: any sign, any exponent (denormals too). */
static inline float random_finite(void)
{
    for (;;) {
        uint32_t bits = rng() ^ (rng() << 16);
        float f;
        memcpy(&f, &bits, sizeof f);
        if (isfinite(f)) return f;
    }
}

static inline int same_bits(float a, float b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* Makes g_dir, a fresh folder under /tmp named after the test; 0 on failure. */
static inline int test_dir_begin(const char* name)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/veil_%s_XXXXXX", name);
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 0;
    }
    return 1;
}

/* Checks that the tests left nothing behind in g_dir, and removes it. */
static inline int test_dir_end(void)
{
    int left = count_entries(g_dir, NULL);
    if (left != 0) fprintf(stderr, "%d files left in %s\n", left, g_dir);
    return left == 0 && rmdir(g_dir) == 0;
}

#endif
