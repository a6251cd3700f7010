/* veil accuracy benchmark — scenes and cached references (see accuracy_scenes.h). */
#define _POSIX_C_SOURCE 200809L
#include "accuracy_scenes.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/hash.h"
#include "io/image.h"
#include "reference/compare.h"
#include "reference/pathtracer.h"
#include "gpu/gl_util.h"

#ifndef VEIL_SOURCE_DIR
#define VEIL_SOURCE_DIR "."
#endif

const char* const acc_scene_names[ACC_SCENE_COUNT] = {"homogeneous", "rbf-fog", "vdb-smoke"};

/* Bumped when what a cached reference means changes. */
#define ACC_REF_FORMAT "veil-accuracy-reference-2"

/* The homogeneous cube: density 1 over [-1, 1]^3 m, optical depth 1.8-2
 * across it; a point light inside it, off every axis, and a sun. The
 * resolution is the fast path's default for it (the library default). */
static const char* const box_json =
    "{\n"
    "  \"camera\": {\"position\": [2.8, 1.6, 4.4], \"look_at\": [0.0, -0.05, 0.0], \"fov_y_deg\": 40,\n"
    "             \"width\": 160, \"height\": 120},\n"
    "  \"medium\": {\"sigma_a\": [0.1, 0.1, 0.1], \"sigma_s\": [0.8, 0.85, 0.9],\n"
    "             \"phase\": {\"type\": \"hg\", \"g\": 0.3}, \"max_resolution\": 128, \"sources\": []},\n"
    "  \"lights\": [\n"
    "    {\"type\": \"point\", \"position\": [-0.37, 0.23, 0.31], \"intensity\": [3.0, 2.2, 1.4]},\n"
    "    {\"type\": \"directional\", \"direction\": [0.35, -0.8, -0.45], \"irradiance\": [1.4, 1.5, 1.7]}\n"
    "  ],\n"
    "  \"background\": {\"color\": [0.02, 0.022, 0.03]}\n"
    "}\n";

static const char* const scene_files[ACC_SCENE_COUNT] = {NULL, "data/scenes/rbf_fog.json",
                                                         "data/scenes/vdb_smoke.json"};

/* Hashes a whole file into h; 0 when it cannot be read. */
static int hash_file(const char* path, uint64_t* h)
{
    FILE* f = fopen(path, "rb");
    if (!f) return 0;
    unsigned char buf[1 << 16];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) *h = veil_hash_bytes(*h, buf, n);
    int ok = !ferror(f);
    fclose(f);
    return ok;
}

veil_result acc_scene_load(int id, acc_scene* out, veil_error* err)
{
    memset(out, 0, sizeof *out);
    if (id < 0 || id >= ACC_SCENE_COUNT) return veil_fail(err, VEIL_ERR_INVALID, "no scene %d", id);
    out->id = id;
    out->name = acc_scene_names[id];
    uint64_t h = veil_hash_bytes(VEIL_FNV_OFFSET, out->name, strlen(out->name));
    veil_result res;
    if (id == ACC_HOMOGENEOUS) {
        res = veil_scene_parse("homogeneous (bench/accuracy_scenes.c)", box_json, strlen(box_json), &out->scene, err);
        h = veil_hash_bytes(h, box_json, strlen(box_json));
        out->given_density = 1;
        snprintf(out->source, sizeof out->source,
                 "a cube [-%g, %g]^3 m of density 1 given as a grid (bench/accuracy_scenes.c), "
                 "point light inside, directional light",
                 (double)ACC_BOX_HALF, (double)ACC_BOX_HALF);
    } else {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", VEIL_SOURCE_DIR, scene_files[id]);
        if (id == ACC_VDB_SMOKE) {
            char vdb[1024];
            struct stat st;
            snprintf(vdb, sizeof vdb, "%s/data/generated/smoke_plume.vdb", VEIL_SOURCE_DIR);
            if (stat(vdb, &st) != 0)
                return veil_fail(err, VEIL_ERR_IO,
                                 "%s: %s; it is generated: run `make data` in %s (or leave the scene out: "
                                 "--scenes homogeneous,rbf-fog)",
                                 vdb, strerror(errno), VEIL_SOURCE_DIR);
            if (!hash_file(vdb, &h)) return veil_fail(err, VEIL_ERR_IO, "%s: cannot read it", vdb);
        }
        res = veil_scene_load(path, &out->scene, err);
        if (res == VEIL_OK && !hash_file(path, &h)) res = veil_fail(err, VEIL_ERR_IO, "%s: cannot read it", path);
        snprintf(out->source, sizeof out->source, "%s", scene_files[id]);
    }
    if (res != VEIL_OK) {
        acc_scene_free(out);
        return res;
    }
    /* this benchmark measures the single-scattering march against max-order-1
     * references: multiple scattering (bench/multiple_scattering.py) off */
    out->scene.multiple.screen_space = 0;
    out->scene.multiple.volumetric = 0;
    out->default_res = out->scene.medium.max_resolution;
    out->content_key = h;
    return VEIL_OK;
}

void acc_scene_free(acc_scene* s)
{
    if (!s) return;
    veil_scene_free(&s->scene);
    memset(s, 0, sizeof *s);
}

float* acc_box_density(int n, veil_grid* g)
{
    /* centres at -H + i * 2H / (n - 1): the first and last on the faces */
    g->voxel = 2.0f * ACC_BOX_HALF / (float)(n - 1);
    for (int a = 0; a < 3; ++a) {
        g->dims[a] = n;
        g->origin[a] = -ACC_BOX_HALF - 0.5f * g->voxel;
    }
    size_t nv = veil_grid_voxels(g);
    float* rho = malloc(nv * sizeof(float));
    if (!rho) return NULL;
    for (size_t v = 0; v < nv; ++v) rho[v] = 1.0f;
    return rho;
}

/* ---- the reference cache -------------------------------------------------- */

static uint64_t reference_key(const acc_scene* s, const acc_ref_settings* r)
{
    uint64_t h = veil_hash_bytes(s->content_key, ACC_REF_FORMAT, sizeof ACC_REF_FORMAT);
    int ints[4] = {r->width, r->height, r->spp, r->ref_res};
    h = veil_hash_bytes(h, ints, sizeof ints);
    h = veil_hash_bytes(h, &r->seed, sizeof r->seed);
    /* the code that makes the reference: a fix there makes a new one */
    static const char* const sources[] = {"reference/pathtracer.c", "reference/optical_depth.c",
                                          "reference/closed_forms.c", "volume/scene_volume.c",
                                          "volume/vdb_volume.c", "volume/volume.c", "volume/rbf.c",
                                          "io/vdb.cpp"};
    for (size_t i = 0; i < sizeof sources / sizeof *sources; ++i) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", VEIL_SOURCE_DIR, sources[i]);
        hash_file(path, &h);
    }
    return h;
}

static void cache_path(const char* dir, const acc_scene* s, const acc_ref_settings* r, char* out, size_t len)
{
    snprintf(out, len, "%s/%s-%dx%d-spp%d-res%d-%016llx.exr", dir, s->name, r->width, r->height, r->spp, r->ref_res,
             (unsigned long long)reference_key(s, r));
}

/* mkdir -p */
static veil_result make_dirs(const char* dir, veil_error* err)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", dir);
    for (char* p = buf + 1;; ++p) {
        int end = *p == '\0';
        if (*p == '/' || end) {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return veil_fail(err, VEIL_ERR_IO, "cannot create folder %s: %s", buf, strerror(errno));
            if (end) break;
            *p = '/';
        }
    }
    return VEIL_OK;
}

enum { N_PLANES = 13 };
static const char* const plane_names[N_PLANES] = {"R",        "G",        "B",        "A",        "stderr.R",
                                                  "stderr.G", "stderr.B", "half0.R",  "half0.G",  "half0.B",
                                                  "half1.R",  "half1.G",  "half1.B"};

/* Where plane c of a pixel lives: the buffer and the stride. */
static float* plane_slot(acc_reference* ref, int c, size_t p)
{
    if (c < 4) return &ref->rgba[4 * p + c];
    if (c < 7) return &ref->stderr_rgb[3 * p + c - 4];
    return &ref->half[(c - 7) / 3][4 * p + (c - 7) % 3];
}

static veil_result alloc_reference(acc_reference* ref, veil_error* err)
{
    size_t np = (size_t)ref->width * (size_t)ref->height;
    ref->rgba = malloc(np * 4 * sizeof(float));
    ref->stderr_rgb = malloc(np * 3 * sizeof(float));
    ref->half[0] = malloc(np * 4 * sizeof(float));
    ref->half[1] = malloc(np * 4 * sizeof(float));
    if (!ref->rgba || !ref->stderr_rgb || !ref->half[0] || !ref->half[1])
        return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %dx%d reference", ref->width, ref->height);
    return VEIL_OK;
}

static veil_result cache_read(acc_reference* ref, veil_error* err)
{
    struct stat st;
    if (stat(ref->path, &st) != 0) return VEIL_ERR_IO; /* not cached */
    veil_result res = VEIL_OK;
    for (int c = 0; c < N_PLANES && res == VEIL_OK; ++c) {
        float* plane = NULL;
        int w = 0, h = 0;
        res = veil_read_exr_channel(ref->path, plane_names[c], &w, &h, &plane, err);
        if (res == VEIL_OK && c == 0) {
            ref->width = w;
            ref->height = h;
            res = alloc_reference(ref, err);
        }
        if (res == VEIL_OK && (w != ref->width || h != ref->height))
            res = veil_fail(err, VEIL_ERR_INVALID, "%s: channel %s is %dx%d", ref->path, plane_names[c], w, h);
        size_t np = (size_t)w * (size_t)h;
        for (size_t p = 0; p < np && res == VEIL_OK; ++p) *plane_slot(ref, c, p) = plane[p];
        free(plane);
    }
    if (res != VEIL_OK) return res;
    size_t np = (size_t)ref->width * (size_t)ref->height;
    for (size_t p = 0; p < np; ++p) ref->half[0][4 * p + 3] = ref->half[1][4 * p + 3] = ref->rgba[4 * p + 3];
    char side[1100];
    snprintf(side, sizeof side, "%s.txt", ref->path);
    FILE* f = fopen(side, "r");
    ref->ms = NAN;
    if (f) {
        if (fscanf(f, "ms %lf grid %d %d %d", &ref->ms, &ref->grid_dims[0], &ref->grid_dims[1], &ref->grid_dims[2]) !=
            4)
            ref->ms = NAN;
        fclose(f);
    }
    ref->from_cache = 1;
    return VEIL_OK;
}

static veil_result cache_write(acc_reference* ref, veil_error* err)
{
    size_t np = (size_t)ref->width * (size_t)ref->height;
    float* planes = malloc(np * N_PLANES * sizeof(float));
    if (!planes) return veil_fail(err, VEIL_ERR_OOM, "out of memory");
    const float* ptrs[N_PLANES];
    for (int c = 0; c < N_PLANES; ++c) {
        float* pl = planes + (size_t)c * np;
        for (size_t p = 0; p < np; ++p) pl[p] = *plane_slot(ref, c, p);
        ptrs[c] = pl;
    }
    veil_result res = veil_write_exr_planes(ref->path, ref->width, ref->height, N_PLANES, plane_names, ptrs, err);
    free(planes);
    if (res != VEIL_OK) return res;
    char side[1100];
    snprintf(side, sizeof side, "%s.txt", ref->path);
    FILE* f = fopen(side, "w");
    if (f) {
        fprintf(f, "ms %.3f grid %d %d %d\n", ref->ms, ref->grid_dims[0], ref->grid_dims[1], ref->grid_dims[2]);
        fclose(f);
    }
    return VEIL_OK;
}

typedef struct progress_state {
    const char* name;
    double t0;
} progress_state;

static void progress(void* user, int rows_done, int rows_total)
{
    const progress_state* p = user;
    fprintf(stderr, "\r[%s] reference: %d/%d rows, %.0f s", p->name, rows_done, rows_total,
            (veil_now_ms() - p->t0) / 1000.0);
    if (rows_done == rows_total) fputc('\n', stderr);
}

static veil_result render_reference(const acc_scene* s, const acc_ref_settings* r, acc_reference* ref,
                                    veil_error* err)
{
    veil_pt_medium* m = NULL;
    veil_result res;
    double t0 = veil_now_ms();
    if (s->given_density) {
        veil_grid g;
        float* rho = acc_box_density(ACC_BOX_REF_N, &g);
        if (!rho) return veil_fail(err, VEIL_ERR_OOM, "out of memory");
        res = veil_pt_medium_from_density(&s->scene, &g, rho, &m, err);
        free(rho);
    } else {
        veil_scene fine = s->scene; /* shallow: only the resolution differs */
        fine.medium.max_resolution = r->ref_res;
        fprintf(stderr, "[%s] reference: voxelising the medium at %d (CPU)\n", s->name, r->ref_res);
        res = veil_pt_medium_from_scene(&fine, &m, err);
    }
    if (res != VEIL_OK) return res;
    const veil_grid* g = veil_pt_medium_grid(m);
    if (g && !s->given_density) memcpy(ref->grid_dims, g->dims, sizeof ref->grid_dims);
    fprintf(stderr, "[%s] reference medium ready in %.1f s\n", s->name, (veil_now_ms() - t0) / 1000.0);
    ref->width = r->width;
    ref->height = r->height;
    res = alloc_reference(ref, err);
    float *rgba[2] = {NULL, NULL}, *se[2] = {NULL, NULL};
    for (int k = 0; k < 2 && res == VEIL_OK; ++k) {
        progress_state ps = {s->name, veil_now_ms()};
        veil_pt_opts o = {.width = r->width, .height = r->height, .spp = r->spp / 2, .max_order = 1,
                          .seed = r->seed + (uint64_t)k, .progress = progress, .progress_user = &ps};
        veil_pt_stats st = {0};
        fprintf(stderr, "[%s] reference half %d of 2: %d spp\n", s->name, k + 1, o.spp);
        res = veil_pt_render(m, &s->scene, &o, &rgba[k], &se[k], &st, err);
        if (res == VEIL_OK && (st.cut_walks || st.dropped_samples))
            fprintf(stderr, "[%s] reference: WARNING: %llu walks cut, %llu samples dropped\n", s->name,
                    (unsigned long long)st.cut_walks, (unsigned long long)st.dropped_samples);
    }
    veil_pt_medium_free(m);
    size_t np = (size_t)r->width * (size_t)r->height;
    for (size_t p = 0; p < np && res == VEIL_OK; ++p) {
        for (int c = 0; c < 4; ++c) {
            ref->rgba[4 * p + c] = 0.5f * (rgba[0][4 * p + c] + rgba[1][4 * p + c]);
            for (int k = 0; k < 2; ++k) ref->half[k][4 * p + c] = c < 3 ? rgba[k][4 * p + c] : ref->rgba[4 * p + c];
        }
        for (int c = 0; c < 3; ++c) {
            double a = se[0][3 * p + c], b = se[1][3 * p + c];
            ref->stderr_rgb[3 * p + c] = (float)(0.5 * sqrt(a * a + b * b));
        }
    }
    for (int k = 0; k < 2; ++k) {
        free(rgba[k]);
        free(se[k]);
    }
    ref->ms = veil_now_ms() - t0;
    return res;
}

veil_result acc_reference_get(const acc_scene* s, const acc_ref_settings* r, const char* cache_dir,
                              acc_reference* out, veil_error* err)
{
    memset(out, 0, sizeof *out);
    if (cache_dir) {
        veil_result res = make_dirs(cache_dir, err);
        if (res != VEIL_OK) return res;
        cache_path(cache_dir, s, r, out->path, sizeof out->path);
        veil_error cerr = {0};
        res = cache_read(out, &cerr);
        if (res == VEIL_OK && out->width == r->width && out->height == r->height) return VEIL_OK;
        if (res != VEIL_ERR_IO || cerr.msg[0])
            fprintf(stderr, "[%s] cached reference %s unusable (%s); rendering it again\n", s->name, out->path,
                    cerr.msg[0] ? cerr.msg : "wrong size");
        acc_reference_free(out);
        cache_path(cache_dir, s, r, out->path, sizeof out->path);
    }
    veil_result res = render_reference(s, r, out, err);
    if (res == VEIL_OK && cache_dir) {
        veil_error werr = {0};
        if (cache_write(out, &werr) != VEIL_OK)
            fprintf(stderr, "[%s] could not cache the reference: %s\n", s->name, werr.msg);
    }
    if (res != VEIL_OK) acc_reference_free(out);
    return res;
}

void acc_reference_free(acc_reference* ref)
{
    if (!ref) return;
    free(ref->rgba);
    free(ref->stderr_rgb);
    free(ref->half[0]);
    free(ref->half[1]);
    ref->rgba = ref->stderr_rgb = ref->half[0] = ref->half[1] = NULL;
}

/* ---- noise and binning ------------------------------------------------------ */

/* rms over values of stderr / max(|ref|, floor) */
static double reference_noise(const acc_reference* ref, double floor)
{
    size_t np = (size_t)ref->width * (size_t)ref->height;
    double sum = 0.0;
    for (size_t p = 0; p < np; ++p)
        for (int c = 0; c < 3; ++c) {
            double den = fmax(fabs(ref->rgba[4 * p + c]), floor), e = ref->stderr_rgb[3 * p + c] / den;
            sum += e * e;
        }
    return np ? sqrt(sum / (3.0 * (double)np)) : NAN;
}

/* The same with |h0 - h1| / 2 for the standard error of the mean of the
 * halves (its expected square is the mean's variance). */
static double split_noise(const float* h0, const float* h1, const float* ref, size_t np, double floor)
{
    double sum = 0.0;
    for (size_t p = 0; p < np; ++p)
        for (int c = 0; c < 3; ++c) {
            double den = fmax(fabs(ref[4 * p + c]), floor), e = 0.5 * (h0[4 * p + c] - h1[4 * p + c]) / den;
            sum += e * e;
        }
    return np ? sqrt(sum / (3.0 * (double)np)) : NAN;
}

float* acc_bin_image(const float* rgba, int w, int h, int b)
{
    int bw = w / b, bh = h / b;
    float* out = calloc((size_t)bw * (size_t)bh * 4, sizeof(float));
    if (!out) return NULL;
    for (int y = 0; y < bh * b; ++y)
        for (int x = 0; x < bw * b; ++x)
            for (int c = 0; c < 4; ++c)
                out[4 * ((size_t)(y / b) * bw + x / b) + c] += rgba[4 * ((size_t)y * w + x) + c] / (float)(b * b);
    return out;
}

static double mean_rgb(const float* rgba, size_t np)
{
    double sum = 0.0;
    for (size_t p = 0; p < np; ++p) sum += (double)rgba[4 * p] + rgba[4 * p + 1] + rgba[4 * p + 2];
    return np ? sum / (3.0 * (double)np) : 0.0;
}

void acc_ref_view_free(acc_ref_view* v);

int acc_ref_view_make(const acc_reference* ref, int bin, acc_ref_view* v)
{
    memset(v, 0, sizeof *v);
    size_t np = (size_t)ref->width * (size_t)ref->height;
    v->bw = ref->width / bin;
    v->bh = ref->height / bin;
    v->bin = acc_bin_image(ref->rgba, ref->width, ref->height, bin);
    v->bin_half[0] = acc_bin_image(ref->half[0], ref->width, ref->height, bin);
    v->bin_half[1] = acc_bin_image(ref->half[1], ref->width, ref->height, bin);
    if (!v->bin || !v->bin_half[0] || !v->bin_half[1]) {
        acc_ref_view_free(v);
        return 0;
    }
    /* the floor veil_compare_images uses by default */
    v->floor = VEIL_COMPARE_FLOOR_FRACTION * mean_rgb(ref->rgba, np);
    double floor_bin = VEIL_COMPARE_FLOOR_FRACTION * mean_rgb(v->bin, (size_t)v->bw * v->bh);
    v->noise_se = reference_noise(ref, v->floor);
    v->noise_split = split_noise(ref->half[0], ref->half[1], ref->rgba, np, v->floor);
    v->noise_bin = split_noise(v->bin_half[0], v->bin_half[1], v->bin, (size_t)v->bw * v->bh, floor_bin);
    return 1;
}

void acc_ref_view_free(acc_ref_view* v)
{
    free(v->bin);
    free(v->bin_half[0]);
    free(v->bin_half[1]);
    memset(v, 0, sizeof *v);
}
