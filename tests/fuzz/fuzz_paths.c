/* libFuzzer target: frame patterns and the files of a run (issue 22) --
 * scene/frame_pattern.h and cli/run_files.h by name only (no file is
 * touched). The input is split at newlines into: a range ("9-10x2"), the
 * -o pattern, the --png pattern, a file the run reads, a sequence it reads
 * (a pattern, its frame offset 1), and one more file it writes (a contact
 * sheet). Checked:
 *  - a pattern names each frame of the range by a file of its own (the
 *    number is written whole, so two frames never share a name);
 *  - veil_run_files_check agrees with a plain oracle written here: every
 *    file's name normalised by a stack of its components, every pair
 *    compared, the first problem taken in the order the header states;
 *  - every clash has a sentence. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/run_files.h"
#include "frame/frames.h"
#include "scene/frame_pattern.h"

enum { MAX_FRAMES = 48, MAX_FILES = 6, NAME = 4096 };

/* The oracle's normal form: components on a stack ("." dropped, ".." pops a
 * name, stays at the start of a relative path, vanishes after "/"). */
static int normal(const char* path, char* out, size_t n)
{
    const char* parts[NAME / 2];
    size_t lens[NAME / 2], k = 0, lead = 0; /* lead: the leading ".." kept */
    int absolute = path[0] == '/';
    for (const char* p = path; *p;) {
        while (*p == '/') ++p;
        const char* e = p;
        while (*e && *e != '/') ++e;
        size_t len = (size_t)(e - p);
        if (len == 0 || (len == 1 && *p == '.')) {
            p = e;
            continue;
        }
        if (len == 2 && p[0] == '.' && p[1] == '.') {
            if (k > lead) {
                --k;
                p = e;
                continue;
            }
            if (absolute) {
                p = e;
                continue;
            }
            ++lead;
        }
        if (k == NAME / 2) return 0;
        parts[k] = p, lens[k] = len, ++k;
        p = e;
    }
    size_t w = 0;
    if (absolute) {
        if (n < 2) return 0;
        out[w++] = '/';
    }
    for (size_t i = 0; i < k; ++i) {
        if (w + lens[i] + 2 > n) return 0;
        if (i) out[w++] = '/';
        memcpy(out + w, parts[i], lens[i]);
        w += lens[i];
    }
    out[w] = '\0';
    return 1;
}

/* A file's key by the oracle: its folder's normal form, '/', its name; or its own problem. */
static veil_run_problem key(const char* path, char* out, size_t n)
{
    if (!path[0]) return VEIL_RUN_EMPTY;
    const char* slash = strrchr(path, '/');
    const char* base = slash ? slash + 1 : path;
    if (!*base || !strcmp(base, ".") || !strcmp(base, "..")) return VEIL_RUN_DIRECTORY;
    char dir[NAME], norm[NAME];
    size_t len = slash ? (slash == path ? 1 : (size_t)(slash - path)) : 0;
    memcpy(dir, path, len);
    dir[len] = '\0';
    if (!normal(dir, norm, sizeof norm)) return VEIL_RUN_FINE + 100; /* too long: not compared */
    int w = snprintf(out, n, "%s%s%s", norm, norm[0] && strcmp(norm, "/") ? "/" : "", base);
    return w > 0 && (size_t)w < n ? VEIL_RUN_FINE : VEIL_RUN_FINE + 100;
}

typedef struct item {
    int file, framed;
    long frame;
    char path[NAME], key[NAME];
    veil_run_problem own;
} item;

static item items[MAX_FILES * (MAX_FRAMES + 1)];

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    if (size > 4 * NAME) return 0;
    char text[4 * NAME + 1];
    memcpy(text, data, size);
    text[size] = '\0';
    const char* field[6] = {"", "", "", "", "", ""};
    int nf = 0;
    for (char* p = text; nf < 6 && p;) {
        field[nf++] = p;
        p = strchr(p, '\n');
        if (p) *p++ = '\0';
    }
    if (nf < 3) return 0;
    veil_error err = {0};
    veil_frame_range range = {1, 2, 1};
    if (veil_frame_range_parse(field[0], &range, &err) != VEIL_OK) range = (veil_frame_range){1, 2, 1};
    if (veil_frame_range_count(&range) > MAX_FRAMES) range.last = range.first + (MAX_FRAMES - 1) * range.step;
    long count = veil_frame_range_count(&range);

    /* the patterns: each frame's own file */
    for (int k = 1; k <= 4; ++k) {
        if (veil_frame_pattern_kind(field[k]) != 1) continue;
        static char seen[MAX_FRAMES][NAME];
        int ok = 1;
        for (long i = 0; i < count && ok; ++i) {
            veil_error e = {0};
            if (veil_frame_pattern_path(field[k], veil_frame_range_at(&range, i), seen[i], NAME, &e) != VEIL_OK) {
                if (!e.msg[0]) abort(); /* every refusal says why */
                ok = 0;
            }
            for (long j = 0; ok && j < i; ++j)
                if (!strcmp(seen[i], seen[j])) abort(); /* two frames, one name */
        }
    }

    /* the run */
    veil_run_file files[MAX_FILES];
    int n = 0;
    const char* staged = ".veil-staged42";
    if (veil_frame_pattern_kind(field[3]) >= 0 && field[3][0])
        files[n++] = (veil_run_file){.what = "the scene", .path = field[3]};
    if (veil_frame_pattern_kind(field[4]) == 1)
        files[n++] = (veil_run_file){.what = "a sequence", .path = field[4], .naming = VEIL_RUN_PATTERN, .offset = 1};
    if (veil_frame_pattern_kind(field[1]) == 1)
        files[n++] = (veil_run_file){.what = "-o", .path = field[1], .naming = VEIL_RUN_PATTERN, .writes = 1,
                                     .staged = staged};
    if (veil_frame_pattern_kind(field[2]) == 1)
        files[n++] = (veil_run_file){.what = "--png", .path = field[2], .naming = VEIL_RUN_PATTERN, .writes = 1,
                                     .staged = staged};
    if (nf > 5) files[n++] = (veil_run_file){.what = "--contact-sheet", .path = field[5], .writes = 1};
    static veil_run_clash clash;
    veil_result r = veil_run_files_check(files, n, &range, 0, &clash, &err);
    if (r != VEIL_OK) {
        if (!err.msg[0]) abort();
        return 0;
    }
    char sentence[VEIL_ERROR_MAX];
    veil_run_clash_text(files, &clash, sentence, sizeof sentence);
    if ((clash.problem != VEIL_RUN_FINE) != (sentence[0] != '\0')) abort();

    /* the oracle: every file of the run, in the check's order (the files of the whole run, then each frame) */
    size_t m = 0;
    for (long slot = 0; slot <= count; ++slot)
        for (int g = 0; g < n; ++g) {
            if ((slot == 0) != (files[g].naming == VEIL_RUN_ONE)) continue;
            item* it = &items[m];
            it->file = g, it->framed = slot > 0, it->frame = slot ? veil_frame_range_at(&range, slot - 1) : 0;
            veil_error e = {0};
            if (veil_run_file_path(&files[g], it->frame, it->path, NAME, &e) != VEIL_OK) return 0; /* the check erred */
            it->own = key(it->path, it->key, NAME);
            if (it->own == VEIL_RUN_FINE + 100) return 0;
            ++m;
        }
    /* a write's own problem first: the first in order */
    for (size_t i = 0; i < m; ++i)
        if (files[items[i].file].writes && items[i].own != VEIL_RUN_FINE) {
            if (clash.problem != items[i].own || clash.a != items[i].file || clash.frame_a != items[i].frame) abort();
            return 0;
        }
    /* else the pair whose later file comes first, then whose earlier does; one of them written */
    long later = -1, earlier = -1;
    veil_run_problem want = VEIL_RUN_FINE;
    for (size_t j = 0; j < m && later < 0; ++j)
        for (size_t i = 0; i < j && later < 0; ++i) {
            const item *a = &items[i], *b = &items[j];
            int wa = files[a->file].writes, wb = files[b->file].writes;
            if (a->own != VEIL_RUN_FINE || b->own != VEIL_RUN_FINE) continue; /* an input not named as a file */
            char sa[NAME + 32], sb[NAME + 32];
            snprintf(sa, sizeof sa, "%s%s", a->key, staged);
            snprintf(sb, sizeof sb, "%s%s", b->key, staged);
            if ((wa || wb) && !strcmp(a->key, b->key)) want = VEIL_RUN_SAME_NAME;
            else if (wa && files[a->file].staged && !wb && !strcmp(sa, b->key)) want = VEIL_RUN_STAGED;
            else if (wb && files[b->file].staged && !wa && !strcmp(sb, a->key)) want = VEIL_RUN_STAGED;
            else continue;
            later = (long)j, earlier = (long)i;
        }
    if (want != clash.problem) abort();
    if (want == VEIL_RUN_FINE) return 0;
    /* the check names the written one first (of two written, the later) */
    const item *l = &items[later], *e = &items[earlier];
    const item* a = files[l->file].writes ? l : e;
    const item* b = a == l ? e : l;
    if (clash.a != a->file || clash.frame_a != a->frame || clash.b != b->file || clash.frame_b != b->frame) abort();
    if (strcmp(clash.path_a, a->path) || strcmp(clash.path_b, b->path)) abort();
    return 0;
}
