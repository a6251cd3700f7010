/* veil — the files of a run, checked against each other (cli/run_files.h). */
#define _XOPEN_SOURCE 700
#include "run_files.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/hash.h"
#include "frame/plan.h"
#include "scene/frame_pattern.h"

enum {
    NAME_MAX_BYTES = 4096, /* a file's name as the commands make it (their buffers) */
    KEY_MAX = 8192,        /* a folder's real path (PATH_MAX) and the rest of the name */
    DIR_CACHE = 8          /* folders remembered: a run names a few, over and over (each frame's EXR and PNG) */
};

/* A file of the run: the hash of its key (or its identity) and which it is:
 * id = slot * n + file, slot 0 for the files of the whole run, 1 + i for
 * frame i of the range. Sorted by (h, id): equal hashes meet, in order. */
typedef struct rec {
    uint64_t h, id;
} rec;

typedef struct dir_entry {
    char dir[NAME_MAX_BYTES];
    char key[KEY_MAX];
    char detail[NAME_MAX_BYTES];
    veil_run_problem problem;
    int used;
} dir_entry;

typedef struct ctx {
    const veil_run_file* files;
    int n;
    const veil_frame_range* range;
    long count; /* frames */
    int use_fs;
    char cwd[NAME_MAX_BYTES];
    dir_entry cache[DIR_CACHE];
    int next;
    veil_error* err;
    /* scratch for names and keys (the context is on the heap, not the stack) */
    char px[NAME_MAX_BYTES], py[NAME_MAX_BYTES], kx[KEY_MAX], ky[KEY_MAX];
    char path[NAME_MAX_BYTES], key[KEY_MAX], detail[NAME_MAX_BYTES], ipath[NAME_MAX_BYTES], ikey[KEY_MAX];
} ctx;

static int less(const rec* x, const rec* y) { return x->h < y->h || (x->h == y->h && x->id < y->id); }

static void swap(rec* x, rec* y)
{
    rec t = *x;
    *x = *y, *y = t;
}

static void sift_down(rec* r, size_t i, size_t n)
{
    for (size_t c; (c = 2 * i + 1) < n; i = c) {
        if (c + 1 < n && less(&r[c], &r[c + 1])) ++c;
        if (!less(&r[i], &r[c])) return;
        swap(&r[i], &r[c]);
    }
}

/* Sorts r[0 .. n) by (h, id) in place (qsort's merge sort takes a copy as large: 64 MB more for a
 * day of film): quicksort on the median of three, heapsort past 2 log2(n) levels, insertion sort below
 * 16 elements. */
static void sort_recs(rec* r, size_t n, int depth)
{
    while (n > 16) {
        if (depth-- == 0) {
            for (size_t i = n / 2; i > 0; --i) sift_down(r, i - 1, n);
            for (size_t k = n - 1; k > 0; --k) {
                swap(&r[0], &r[k]);
                sift_down(r, 0, k);
            }
            return;
        }
        size_t m = n / 2;
        if (less(&r[m], &r[0])) swap(&r[m], &r[0]);
        if (less(&r[n - 1], &r[0])) swap(&r[n - 1], &r[0]);
        if (less(&r[n - 1], &r[m])) swap(&r[n - 1], &r[m]);
        rec pivot = r[m];
        size_t i = 0, j = n - 1;
        for (;;) { /* Hoare: r[0 .. j] <= pivot <= r[j + 1 .. n) */
            while (less(&r[i], &pivot)) ++i;
            while (less(&pivot, &r[j])) --j;
            if (i >= j) break;
            swap(&r[i++], &r[j--]);
        }
        /* the smaller side by recursion, the larger by the loop: a stack of log2(n) */
        size_t left = j + 1;
        if (left < n - left) {
            sort_recs(r, left, depth);
            r += left, n -= left;
        } else {
            sort_recs(r + left, n - left, depth);
            n = left;
        }
    }
    for (size_t i = 1; i < n; ++i)
        for (size_t k = i; k > 0 && less(&r[k], &r[k - 1]); --k) swap(&r[k], &r[k - 1]);
}

static void sort_all(rec* r, size_t n)
{
    int depth = 0;
    for (size_t k = n; k > 1; k >>= 1) depth += 2;
    sort_recs(r, n, depth);
}

static int copy(char* out, size_t n, const char* s)
{
    size_t len = strlen(s);
    if (len >= n) return 0;
    memcpy(out, s, len + 1);
    return 1;
}

/* in, its components normalised as written: "." dropped, ".." taking the
 * one before it (kept at the start of a relative path, dropped after "/"),
 * repeated '/' one. An absolute path keeps its '/', a relative one that
 * comes to nothing is "". 0 when it does not fit. */
static int lexical(const char* in, char* out, size_t n)
{
    int absolute = in[0] == '/';
    size_t k = 0, keep = 0; /* keep: the leading "../" of a relative path, never taken back */
    if (n < 2) return 0;
    if (absolute) out[k++] = '/', keep = 1;
    out[k] = '\0';
    for (const char* p = in; *p;) {
        while (*p == '/') ++p;
        const char* e = p;
        while (*e && *e != '/') ++e;
        size_t len = (size_t)(e - p);
        if (len == 0 || (len == 1 && p[0] == '.')) {
            p = e;
            continue;
        }
        if (len == 2 && p[0] == '.' && p[1] == '.') {
            if (k > keep) { /* drop the last component */
                while (k > keep && out[k - 1] != '/') --k;
                if (k > keep) --k; /* its '/' */
                out[k] = '\0';
                p = e;
                continue;
            }
            if (absolute) { /* "/.." is "/" */
                p = e;
                continue;
            }
        }
        size_t need = (k > (size_t)absolute ? 1 : 0) + len;
        if (k + need + 1 > n) return 0;
        if (k > (size_t)absolute) out[k++] = '/';
        memcpy(out + k, p, len);
        k += len;
        out[k] = '\0';
        if (!absolute && len == 2 && p[0] == '.' && p[1] == '.') keep = k; /* a leading ".." */
        p = e;
    }
    return 1;
}

/* The folder's key: its real path, or its nearest existing ancestor's and
 * the rest as written; lexical alone without use_fs. */
static veil_run_problem folder_key(ctx* c, const char* dir, char* out, size_t n, char* detail, veil_result* r)
{
    if (!c->use_fs) {
        if (!lexical(dir, out, n)) *r = veil_fail(c->err, VEIL_ERR_LIMIT, "'%s': the name is too long", dir);
        return VEIL_RUN_FINE;
    }
    char abs[KEY_MAX + NAME_MAX_BYTES];
    size_t cwd_len = dir[0] == '/' ? 0 : strlen(c->cwd) + 1;
    int w = dir[0] == '/' ? snprintf(abs, sizeof abs, "%s", dir) : snprintf(abs, sizeof abs, "%s/%s", c->cwd, dir);
    if (w < 0 || (size_t)w >= sizeof abs) {
        *r = veil_fail(c->err, VEIL_ERR_LIMIT, "'%s': the name is too long", dir);
        return VEIL_RUN_FINE;
    }
    size_t p = (size_t)w; /* abs[0 .. p) is tried; abs + p is the rest, not made yet */
    for (;;) {
        char cur[KEY_MAX + NAME_MAX_BYTES], real[KEY_MAX];
        if (p == 0) {
            cur[0] = '/', cur[1] = '\0';
        } else {
            memcpy(cur, abs, p);
            cur[p] = '\0';
        }
        /* realpath(3) with a buffer of PATH_MAX bytes: KEY_MAX is twice that */
        if (realpath(cur, real)) {
            struct stat st;
            if (stat(real, &st) != 0 || !S_ISDIR(st.st_mode)) {
                /* as written: the part of dir it is */
                const char* shown = p > cwd_len ? cur + cwd_len : ".";
                if (p == 0) shown = "/";
                snprintf(detail, NAME_MAX_BYTES, "%.4000s", shown);
                return VEIL_RUN_NOT_FOLDER;
            }
            /* the rest as written, on the real path (which holds no link, so its ".." are its parents):
             * "x/../../y" below a folder not made yet is the real path's parent's y, as mkdir -p makes it */
            char joined[KEY_MAX + NAME_MAX_BYTES];
            int m = snprintf(joined, sizeof joined, "%s/%s", real, abs + p);
            if (m < 0 || (size_t)m >= sizeof joined || !lexical(joined, out, n)) break;
            return VEIL_RUN_FINE;
        }
        if (errno != ENOENT && errno != ENOTDIR) {
            *r = veil_fail(c->err, VEIL_ERR_IO, "'%s': cannot look into the folder: %s", dir, strerror(errno));
            return VEIL_RUN_FINE;
        }
        /* not there yet: its parent */
        while (p > 0 && abs[p - 1] != '/') --p;
        while (p > 0 && abs[p - 1] == '/') --p;
    }
    *r = veil_fail(c->err, VEIL_ERR_LIMIT, "'%s': the name is too long", dir);
    return VEIL_RUN_FINE;
}

/* path's key: its folder's key, '/', its name. */
static veil_run_problem key_of(ctx* c, const char* path, char* out, size_t n, char* detail, veil_result* r)
{
    if (!path[0]) return VEIL_RUN_EMPTY;
    const char* slash = strrchr(path, '/');
    const char* base = slash ? slash + 1 : path;
    if (!base[0] || !strcmp(base, ".") || !strcmp(base, "..")) return VEIL_RUN_DIRECTORY;
    char dir[NAME_MAX_BYTES];
    if (!slash) {
        strcpy(dir, ".");
    } else if (slash == path) {
        strcpy(dir, "/");
    } else {
        size_t len = (size_t)(slash - path);
        if (len >= sizeof dir) {
            *r = veil_fail(c->err, VEIL_ERR_LIMIT, "'%s': the name is too long", path);
            return VEIL_RUN_FINE;
        }
        memcpy(dir, path, len);
        dir[len] = '\0';
    }
    dir_entry* e = NULL;
    for (int i = 0; i < DIR_CACHE && !e; ++i)
        if (c->cache[i].used && !strcmp(c->cache[i].dir, dir)) e = &c->cache[i];
    if (!e) {
        e = &c->cache[c->next];
        c->next = (c->next + 1) % DIR_CACHE;
        e->used = 0;
        veil_result fr = VEIL_OK;
        e->problem = folder_key(c, dir, e->key, sizeof e->key, e->detail, &fr);
        if (fr != VEIL_OK) {
            *r = fr;
            return VEIL_RUN_FINE;
        }
        strcpy(e->dir, dir);
        e->used = 1;
    }
    if (e->problem != VEIL_RUN_FINE) {
        strcpy(detail, e->detail);
        return e->problem;
    }
    const char* sep = e->key[0] && strcmp(e->key, "/") ? "/" : "";
    int m = snprintf(out, n, "%s%s%s", e->key, sep, base);
    if (m < 0 || (size_t)m >= n) *r = veil_fail(c->err, VEIL_ERR_LIMIT, "'%s': the name is too long", path);
    return VEIL_RUN_FINE;
}

static long frame_of(const ctx* c, uint64_t slot) { return veil_frame_range_at(c->range, (long)slot - 1); }

veil_result veil_run_file_path(const veil_run_file* f, long frame, char* out, size_t n, veil_error* err)
{
    if (f->naming == VEIL_RUN_ONE) {
        if (!copy(out, n, f->path)) return veil_fail(err, VEIL_ERR_LIMIT, "'%s': the name is too long", f->path);
        return VEIL_OK;
    }
    if (f->naming == VEIL_RUN_NUMBERED) return veil_frame_path(f->path, frame, 1, out, n, err);
    return veil_frame_pattern_path(f->path, frame + f->offset, out, n, err);
}

/* The file `g` names in `slot`. */
static veil_result path_of(ctx* c, int g, uint64_t slot, char* out, size_t n)
{
    return veil_run_file_path(&c->files[g], slot ? frame_of(c, slot) : 0, out, n, c->err);
}

/* id's file and key; 1, or 0 when it has none (a name with a problem of its own) or on an error. */
static int key_of_id(ctx* c, uint64_t id, char* path, char* key, veil_result* r)
{
    char detail[NAME_MAX_BYTES];
    *r = path_of(c, (int)(id % (uint64_t)c->n), id / (uint64_t)c->n, path, NAME_MAX_BYTES);
    if (*r != VEIL_OK) return 0;
    return key_of(c, path, key, KEY_MAX, detail, r) == VEIL_RUN_FINE && *r == VEIL_OK;
}

static uint64_t identity_hash(const struct stat* st)
{
    uint64_t h = veil_hash_bytes(VEIL_FNV_OFFSET, &st->st_dev, sizeof st->st_dev);
    return veil_hash_bytes(h, &st->st_ino, sizeof st->st_ino);
}

static int writes(const ctx* c, uint64_t id) { return c->files[id % (uint64_t)c->n].writes; }

/* The best clash so far: the one whose later file comes first, then whose earlier does. */
typedef struct best {
    veil_run_problem problem;
    uint64_t later, earlier;
} best;

static void consider(best* b, veil_run_problem p, uint64_t x, uint64_t y)
{
    uint64_t later = x > y ? x : y, earlier = x > y ? y : x;
    if (b->problem == VEIL_RUN_FINE || later < b->later || (later == b->later && earlier < b->earlier) ||
        (later == b->later && earlier == b->earlier && p < b->problem))
        *b = (best){p, later, earlier};
}

/* Two records are one file: by key (same_file 0) or by identity (1). */
static int same(ctx* c, uint64_t x, uint64_t y, int same_file, veil_result* r)
{
    if (!same_file) return key_of_id(c, x, c->px, c->kx, r) && key_of_id(c, y, c->py, c->ky, r) && !strcmp(c->kx, c->ky);
    struct stat sx, sy;
    *r = path_of(c, (int)(x % (uint64_t)c->n), x / (uint64_t)c->n, c->px, sizeof c->px);
    if (*r == VEIL_OK) *r = path_of(c, (int)(y % (uint64_t)c->n), y / (uint64_t)c->n, c->py, sizeof c->py);
    return *r == VEIL_OK && stat(c->px, &sx) == 0 && stat(c->py, &sy) == 0 && sx.st_dev == sy.st_dev &&
           sx.st_ino == sy.st_ino;
}

/* The runs of equal hashes in sorted recs: the first pair in each that is one file and not two inputs. */
static veil_result find_pairs(ctx* c, const rec* recs, size_t count, int same_file, best* b)
{
    veil_result r = VEIL_OK;
    size_t* writers = NULL;
    size_t cap = 0;
    for (size_t s = 0; s < count && r == VEIL_OK;) {
        size_t e = s + 1;
        while (e < count && recs[e].h == recs[s].h) ++e;
        size_t nw = 0;
        if (e - s > cap) {
            free(writers);
            cap = e - s;
            writers = malloc(cap * sizeof *writers);
            if (!writers) return veil_fail(c->err, VEIL_ERR_OOM, "out of memory");
        }
        int found = 0;
        for (size_t q = s; q < e && !found && r == VEIL_OK; ++q) {
            int qw = writes(c, recs[q].id);
            if (qw) { /* any file before it */
                for (size_t p = s; p < q && !found && r == VEIL_OK; ++p)
                    if (same(c, recs[p].id, recs[q].id, same_file, &r)) found = 1, consider(b, same_file ? VEIL_RUN_SAME_FILE : VEIL_RUN_SAME_NAME, recs[p].id, recs[q].id);
            } else { /* an input: only the outputs before it */
                for (size_t k = 0; k < nw && !found && r == VEIL_OK; ++k)
                    if (same(c, recs[writers[k]].id, recs[q].id, same_file, &r))
                        found = 1, consider(b, same_file ? VEIL_RUN_SAME_FILE : VEIL_RUN_SAME_NAME, recs[writers[k]].id, recs[q].id);
            }
            if (qw) writers[nw++] = q;
        }
        s = e;
    }
    free(writers);
    return r;
}

/* Fills clash from the ids of its two files (a: the output at fault). */
static veil_result describe(ctx* c, veil_run_problem p, uint64_t ida, int64_t idb, veil_run_clash* clash)
{
    clash->problem = p;
    clash->a = (int)(ida % (uint64_t)c->n);
    clash->a_framed = ida / (uint64_t)c->n > 0;
    clash->frame_a = clash->a_framed ? frame_of(c, ida / (uint64_t)c->n) : 0;
    veil_result r = path_of(c, clash->a, ida / (uint64_t)c->n, clash->path_a, sizeof clash->path_a);
    clash->b = -1;
    if (r != VEIL_OK || idb < 0) return r;
    clash->b = (int)((uint64_t)idb % (uint64_t)c->n);
    clash->b_framed = (uint64_t)idb / (uint64_t)c->n > 0;
    clash->frame_b = clash->b_framed ? frame_of(c, (uint64_t)idb / (uint64_t)c->n) : 0;
    return path_of(c, clash->b, (uint64_t)idb / (uint64_t)c->n, clash->path_b, sizeof clash->path_b);
}

/* The records of the files that read (pass 0) or write (pass 1); a write's problem of its own ends the pass. */
static veil_result name_files(ctx* c, int pass, rec* keys, size_t* nk, rec* ids, size_t* ni, const rec* inputs,
                              size_t n_inputs, best* staged, veil_run_clash* clash)
{
    char *path = c->path, *key = c->key, *detail = c->detail;
    for (uint64_t slot = 0; slot <= (uint64_t)c->count; ++slot)
        for (int g = 0; g < c->n; ++g) {
            const veil_run_file* f = &c->files[g];
            if (f->writes != pass || (slot == 0) != (f->naming == VEIL_RUN_ONE)) continue;
            uint64_t id = slot * (uint64_t)c->n + (uint64_t)g;
            veil_result r = path_of(c, g, slot, path, sizeof c->path);
            if (r != VEIL_OK) return r;
            veil_run_problem p = key_of(c, path, key, sizeof c->key, detail, &r);
            if (r != VEIL_OK) return r;
            if (p != VEIL_RUN_FINE) {
                if (!pass) continue; /* an input named so cannot be read: its own reader says so */
                r = describe(c, p, id, -1, clash);
                strcpy(clash->detail, detail);
                return r;
            }
            keys[(*nk)++] = (rec){veil_hash_bytes(VEIL_FNV_OFFSET, key, strlen(key)), id};
            struct stat st;
            if (c->use_fs && stat(path, &st) == 0) {
                if (pass && f->scratch) p = VEIL_RUN_EXISTS;
                else if (pass && S_ISDIR(st.st_mode)) p = VEIL_RUN_DIRECTORY;
                else if (pass && !S_ISREG(st.st_mode)) p = VEIL_RUN_NOT_REGULAR;
                if (p != VEIL_RUN_FINE) return describe(c, p, id, -1, clash);
                ids[(*ni)++] = (rec){identity_hash(&st), id};
            }
            if (!pass || !f->staged) continue;
            /* its staging name against the inputs (sorted): the key and the suffix, hashed on */
            uint64_t h = veil_hash_bytes(keys[*nk - 1].h, f->staged, strlen(f->staged));
            size_t lo = 0, hi = n_inputs;
            while (lo < hi) {
                size_t mid = lo + (hi - lo) / 2;
                if (inputs[mid].h < h) lo = mid + 1;
                else hi = mid;
            }
            for (; lo < n_inputs && inputs[lo].h == h; ++lo) {
                char staged_key[KEY_MAX + 64];
                snprintf(staged_key, sizeof staged_key, "%s%s", key, f->staged);
                if (!key_of_id(c, inputs[lo].id, c->ipath, c->ikey, &r) && r != VEIL_OK) return r;
                if (!strcmp(c->ikey, staged_key)) consider(staged, VEIL_RUN_STAGED, id, inputs[lo].id);
            }
        }
    return VEIL_OK;
}

veil_result veil_run_files_check(const veil_run_file* files, int n, const veil_frame_range* range, int use_fs,
                                 veil_run_clash* clash, veil_error* err)
{
    memset(clash, 0, sizeof *clash);
    clash->a = clash->b = -1;
    ctx* c = calloc(1, sizeof *c);
    if (!c) return veil_fail(err, VEIL_ERR_OOM, "out of memory");
    *c = (ctx){.files = files, .n = n, .range = range, .count = range ? veil_frame_range_count(range) : 0,
               .use_fs = use_fs, .err = err};
    if (use_fs && !getcwd(c->cwd, sizeof c->cwd)) {
        free(c);
        return veil_fail(err, VEIL_ERR_IO, "cannot name the current folder: %s", strerror(errno));
    }
    size_t total = 0;
    for (int g = 0; g < n; ++g) {
        if (files[g].naming != VEIL_RUN_ONE && !range) {
            free(c);
            return veil_fail(err, VEIL_ERR_INVALID, "%s: a file per frame, and no frames", files[g].what);
        }
        total += files[g].naming == VEIL_RUN_ONE ? 1 : (size_t)c->count;
    }
    rec* keys = malloc((total ? total : 1) * sizeof *keys);
    rec* ids = malloc((total ? total : 1) * sizeof *ids);
    veil_result r = keys && ids ? VEIL_OK : veil_fail(err, VEIL_ERR_OOM, "out of memory for the names of %zu files", total);
    size_t nk = 0, ni = 0;
    best b = {0}, staged = {0};
    /* the inputs first, sorted, for the outputs' staging names to be looked up */
    if (r == VEIL_OK) r = name_files(c, 0, keys, &nk, ids, &ni, NULL, 0, &staged, clash);
    size_t n_inputs = nk;
    if (r == VEIL_OK) sort_all(keys, n_inputs);
    if (r == VEIL_OK) r = name_files(c, 1, keys, &nk, ids, &ni, keys, n_inputs, &staged, clash);
    if (r == VEIL_OK && clash->problem == VEIL_RUN_FINE) {
        sort_all(keys, nk);
        sort_all(ids, ni);
        r = find_pairs(c, keys, nk, 0, &b);
        if (r == VEIL_OK && use_fs) r = find_pairs(c, ids, ni, 1, &b);
        if (r == VEIL_OK && staged.problem != VEIL_RUN_FINE) consider(&b, staged.problem, staged.later, staged.earlier);
        if (r == VEIL_OK && b.problem != VEIL_RUN_FINE) {
            /* a: the output (of two, the later) */
            uint64_t a = b.later, o = b.earlier;
            if (!writes(c, a)) a = b.earlier, o = b.later;
            r = describe(c, b.problem, a, (int64_t)o, clash);
            if (r == VEIL_OK && b.problem == VEIL_RUN_STAGED)
                snprintf(clash->detail, sizeof clash->detail, "%.4000s%s", clash->path_a, files[clash->a].staged);
        }
    }
    free(keys);
    free(ids);
    free(c);
    return r;
}

/* "-o 'f10.exr' (frame 10)" */
static void name(const veil_run_file* f, const char* path, int framed, long frame, char* out, size_t n)
{
    if (framed) snprintf(out, n, "%s '%.1800s' (frame %ld)", f->what, path, frame);
    else snprintf(out, n, "%s '%.1800s'", f->what, path);
}

void veil_run_clash_text(const veil_run_file* files, const veil_run_clash* c, char* out, size_t n)
{
    if (!n) return;
    out[0] = '\0';
    if (c->problem == VEIL_RUN_FINE || c->a < 0) return;
    const veil_run_file* a = &files[c->a];
    char frame[48] = "";
    if (c->a_framed) snprintf(frame, sizeof frame, " (frame %ld)", c->frame_a);
    char na[2000], nb[2000] = "";
    name(a, c->path_a, c->a_framed, c->frame_a, na, sizeof na);
    if (c->b >= 0) name(&files[c->b], c->path_b, c->b_framed, c->frame_b, nb, sizeof nb);
    switch (c->problem) {
    case VEIL_RUN_EMPTY: snprintf(out, n, "%s: an empty path%s", a->what, frame); break;
    case VEIL_RUN_DIRECTORY: snprintf(out, n, "%s: '%.1800s'%s is a directory", a->what, c->path_a, frame); break;
    case VEIL_RUN_NOT_REGULAR:
        snprintf(out, n, "%s: '%.1800s'%s exists and is not a regular file (a FIFO, a device, a socket): renaming "
                 "over it would replace it", a->what, c->path_a, frame);
        break;
    case VEIL_RUN_EXISTS:
        snprintf(out, n, "%s: '%.1800s' exists already (a run that was killed leaves it; remove it)", a->what,
                 c->path_a);
        break;
    case VEIL_RUN_NOT_FOLDER:
        snprintf(out, n, "%s: '%.1800s'%s: its folder '%.1800s' is a file", a->what, c->path_a, frame, c->detail);
        break;
    case VEIL_RUN_SAME_NAME:
    case VEIL_RUN_SAME_FILE: {
        int link = c->problem == VEIL_RUN_SAME_FILE;
        if (files[c->b].writes)
            snprintf(out, n, "%s and %s are one file%s: each file a run writes needs a name of its own", nb, na,
                     link ? " under two names (a link)" : "");
        else
            snprintf(out, n, "%s is %s%s, which this run reads: it would be overwritten", na, nb,
                     link ? " under another name (a link)" : "");
        break;
    }
    case VEIL_RUN_STAGED:
        snprintf(out, n, "%s is first written as '%.1800s', which is %s, read by this run: it would be overwritten",
                 na, c->detail, nb);
        break;
    case VEIL_RUN_FINE: break;
    }
}
