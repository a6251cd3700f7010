#include "cache.h"
#include "../core/progress.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../gpu/gl_util.h"
#include "../gpu/programs.h"
#include "../scene/solid.h"
#include "../volume/volume.h"

/* Photons a dispatch traces at most (a long dispatch holds the device). */
#define CACHE_DISPATCH_PHOTONS (1 << 18)

#define SPARSE_DEFINE_TEXT "#define VEIL_SPARSE 1\n"
#define SOLID_DEFINE_TEXT "#define VEIL_SOLID 1\n"
static const char* const SPARSE_DEFINE = SPARSE_DEFINE_TEXT;

veil_result veil__cache_programs(veil_cache_programs* p, int sparse, int solid, veil_error* err)
{
    veil_result r = VEIL_OK;
    if (!p->resolve) r = veil_gpu_program("volumetric/shaders/cache_resolve.comp", &p->resolve, err);
    if (r == VEIL_OK && !p->ubo)
        r = veil_gl_buffer(NULL, sizeof(veil_cache_block), GL_DYNAMIC_STORAGE_BIT, "veil cache block", &p->ubo, err);
    if (r == VEIL_OK && !p->bounds[sparse])
        r = sparse ? veil_gpu_program_variant("volumetric/shaders/cache_bounds.comp", SPARSE_DEFINE, "sparse",
                                              &p->bounds[1], err)
                   : veil_gpu_program("volumetric/shaders/cache_bounds.comp", &p->bounds[0], err);
    const int t = 2 * solid + sparse;
    if (r == VEIL_OK && !p->trace[t]) {
        static const char* const defines[4] = {"", SPARSE_DEFINE_TEXT, SOLID_DEFINE_TEXT,
                                               SPARSE_DEFINE_TEXT SOLID_DEFINE_TEXT};
        static const char* const names[4] = {"", "sparse", "solid", "sparse, solid"};
        r = t == 0 ? veil_gpu_program("volumetric/shaders/cache_trace.comp", &p->trace[0], err)
                   : veil_gpu_program_variant("volumetric/shaders/cache_trace.comp", defines[t], names[t], &p->trace[t],
                                              err);
    }
    return r;
}

void veil__cache_programs_free(veil_cache_programs* p)
{
    for (int i = 0; i < 2; ++i) glDeleteProgram(p->bounds[i]);
    for (int i = 0; i < 4; ++i) glDeleteProgram(p->trace[i]);
    glDeleteProgram(p->resolve);
    glDeleteBuffers(1, &p->ubo);
    memset(p, 0, sizeof *p);
}

int veil__cache_grid(const veil_lit_medium* md, int cells, float lo[3], float* h, int dims[3])
{
    float hi[3];
    int any = 0;
    if (md->grid) {
        veil_grid_medium_box(md->grid, lo, hi);
        any = 1;
    }
    /* the fogs' boxes, unless they would make the grid wider than the limit */
    float flo[3], fhi[3];
    int fogs = 0;
    const veil_medium* m = &md->scene->medium;
    for (size_t i = 0; i < m->source_count; ++i) {
        if (m->sources[i].type != VEIL_SOURCE_EXPONENTIAL) continue;
        for (int a = 0; a < 3; ++a) {
            float b0 = m->sources[i].fog.bounds[0][a], b1 = m->sources[i].fog.bounds[1][a];
            flo[a] = fogs ? fminf(flo[a], b0) : b0;
            fhi[a] = fogs ? fmaxf(fhi[a], b1) : b1;
        }
        fogs = 1;
    }
    if (fogs) {
        float ulo[3], uhi[3], longest = 0.0f;
        for (int a = 0; a < 3; ++a) {
            ulo[a] = any ? fminf(lo[a], flo[a]) : flo[a];
            uhi[a] = any ? fmaxf(hi[a], fhi[a]) : fhi[a];
            longest = fmaxf(longest, uhi[a] - ulo[a]);
        }
        if (longest <= VEIL_DIFFUSION_MAX_EXTENT) {
            memcpy(lo, ulo, sizeof ulo);
            memcpy(hi, uhi, sizeof uhi);
            any = 1;
        }
    }
    if (!any) return 0;
    float longest = 0.0f;
    for (int a = 0; a < 3; ++a) longest = fmaxf(longest, hi[a] - lo[a]);
    if (!(longest > 0.0f) || !(longest <= VEIL_DIFFUSION_MAX_EXTENT) || cells < 1) return 0;
    *h = longest / (float)cells;
    for (;;) {
        for (int a = 0; a < 3; ++a) {
            dims[a] = (int)ceilf((hi[a] - lo[a]) / *h);
            if (dims[a] < 1) dims[a] = 1;
            if (dims[a] > cells) dims[a] = cells;
        }
        if ((double)dims[0] * dims[1] * dims[2] <= VEIL_CACHE_MAX_CELLS) return 1;
        *h *= 1.25f; /* coarser until the grid fits its memory (a 512^3 ask would be 7.5 GB) */
    }
}

/* ---- sources ----------------------------------------------------------- */

typedef struct source {
    veil_cache_block b; /* the source's own fields: source.x, y; power (W, all photons); src0..3 */
    double power;       /* luminance W reaching the grid (about): the photons' share */
    double bound;       /* the largest channel of a photon's power times its photons (W) */
    int emitters;       /* the emission: cells in its list; the environment: its table's entries */
    GLuint table;       /* the buffer at VEIL_BIND_CACHE_EMIT while its photons run (the environment's table) */
    long long photons;
} source;

static void sub3(const float* a, const float* b, float* o) { o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2]; }
static float dot3(const float* a, const float* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double lum(const float* c) { return VEIL_LUM_R * c[0] + VEIL_LUM_G * c[1] + VEIL_LUM_B * c[2]; }
static void cross3(const float* a, const float* b, float* o)
{
    o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}
static void normalize3(float* v)
{
    float n = sqrtf(dot3(v, v));
    if (n > 0.0f) v[0] /= n, v[1] /= n, v[2] /= n;
}

/* A sun: a rectangle across its light, upstream of the box, covering the box's shadow. */
static int sun_source(const veil_gpu_light* l, const float lo[3], const float hi[3], source* s)
{
    const float* d = l->direction;
    float t[3] = {fabsf(d[0]) < 0.9f ? 1.0f : 0.0f, fabsf(d[0]) < 0.9f ? 0.0f : 1.0f, 0.0f}, u[3], v[3];
    cross3(d, t, u);
    normalize3(u);
    cross3(d, u, v);
    float umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY, dmin = INFINITY, dmax = -INFINITY;
    for (int k = 0; k < 8; ++k) {
        float c[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        umin = fminf(umin, dot3(c, u)), umax = fmaxf(umax, dot3(c, u));
        vmin = fminf(vmin, dot3(c, v)), vmax = fmaxf(vmax, dot3(c, v));
        dmin = fminf(dmin, dot3(c, d)), dmax = fmaxf(dmax, dot3(c, d));
    }
    float back = dmin - 1e-3f * (dmax - dmin) - 1e-6f; /* the rectangle is just upstream */
    for (int a = 0; a < 3; ++a) {
        s->b.src0[a] = umin * u[a] + vmin * v[a] + back * d[a];
        s->b.src1[a] = (umax - umin) * u[a];
        s->b.src2[a] = (vmax - vmin) * v[a];
        s->b.src3[a] = d[a];
    }
    double area = (double)(umax - umin) * (double)(vmax - vmin);
    for (int c = 0; c < 3; ++c) s->b.power[c] = (float)(l->color[c] * area); /* divided by the photons later */
    s->b.source[0] = VEIL_CACHE_SUN;
    s->power = lum(l->color) * area;
    s->bound = fmax(l->color[0], fmax(l->color[1], l->color[2])) * area;
    return s->power > 0.0;
}

/* A point or spot light: a cone from it covering the box's bounding sphere
 * (the whole sphere from within it), or the spot's own cone where that is narrower. */
static int cone_source(const veil_gpu_light* l, const float lo[3], const float hi[3], source* s)
{
    float c[3], to[3], r2 = 0.0f;
    for (int a = 0; a < 3; ++a) {
        c[a] = 0.5f * (lo[a] + hi[a]);
        r2 += 0.25f * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    sub3(c, l->position, to);
    float d2 = dot3(to, to);
    float axis[3] = {0.0f, 0.0f, 1.0f}, cos_max = -1.0f;
    if (d2 > r2 * 1.0001f) {
        float d = sqrtf(d2);
        for (int a = 0; a < 3; ++a) axis[a] = to[a] / d;
        cos_max = sqrtf(1.0f - r2 / d2);
    }
    if ((int)l->position[3] == VEIL_LIGHT_SPOT && l->color[3] > cos_max) {
        memcpy(axis, l->direction, sizeof axis);
        cos_max = l->color[3];
    }
    double omega = 2.0 * VEIL_PI * (1.0 - (double)cos_max);
    for (int a = 0; a < 3; ++a) {
        s->b.src0[a] = l->position[a];
        s->b.src1[a] = axis[a];
        s->b.power[a] = (float)(l->color[a] * omega);
    }
    s->b.src1[3] = cos_max;
    s->b.source[0] = VEIL_CACHE_CONE;
    s->power = lum(l->color) * omega;
    s->bound = fmax(l->color[0], fmax(l->color[1], l->color[2])) * omega;
    return s->power > 0.0;
}

/* The environment's rest (scene/environment.h) from its table t: photons on a disc across their direction
 * that covers the grid's bounding sphere, upstream of it. */
static int env_source(const veil_environment* e, const veil_env_table* t, const float lo[3], const float hi[3],
                      source* s)
{
    float axes[3][3];
    veil_env_frame(e, axes);
    double r2 = 0.0, d[3];
    for (int a = 0; a < 3; ++a) {
        d[a] = (double)hi[a] - lo[a];
        r2 += 0.25 * d[a] * d[a];
        s->b.src0[a] = 0.5f * (lo[a] + hi[a]);
        s->b.src1[a] = axes[0][a], s->b.src2[a] = axes[1][a], s->b.src3[a] = axes[2][a];
    }
    const double r = sqrt(r2) * 1.001 + 1e-6, area = VEIL_PI * r * r; /* (the disc wholly outside the sphere) */
    s->b.src0[3] = (float)r;
    s->b.src1[3] = (float)e->width, s->b.src2[3] = (float)e->height, s->b.src3[3] = (float)t->block;
    for (int c = 0; c < 3; ++c) s->b.power[c] = (float)(t->total * area); /* times the entry's rgb / lum */
    s->b.source[0] = VEIL_CACHE_ENV;
    /* the luminance entering the grid: the sky's luminance integral times the box's mean projected area,
     * a quarter of its surface (Cauchy); exact for a constant sky */
    s->power = t->total * 0.5 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
    s->bound = t->total * area * t->bound;
    s->emitters = t->n;
    return s->power > 0.0 && t->n > 0;
}

/* ---- the build --------------------------------------------------------- */

static void unbind_all(void)
{
    for (int i = 0; i < 5; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)i, 0);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_CACHE, 0);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MEDIUM, 0);
    glBindImageTexture(VEIL_IMAGE_CACHE, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glBindTextureUnit(VEIL_TEX_EV, 0);
    glBindTextureUnit(VEIL_TEX_EMISSION, 0);
    glBindTextureUnit(VEIL_TEX_SOLID, 0);
    glUseProgram(0);
}

/* An rgba32f field, trilinear, clamped to its edge (the grid covers the medium). */
static veil_result field_texture(const int dims[3], const char* label, GLuint* tex, veil_error* err)
{
    veil_result r = veil_gl_texture3d(GL_RGBA32F, dims, label, tex, err);
    if (r != VEIL_OK) return r;
    static const float zero[4] = {0, 0, 0, 0};
    glClearTexImage(*tex, 0, GL_RGBA, GL_FLOAT, zero);
    return veil_gl_check(label, err);
}

veil_result veil__cache_build(veil_cache_programs* p, const veil_lit_medium* md, const veil_medium_block* mu,
                              const float lo[3], float h, const int dims[3], const veil_cache_settings* s,
                              GLuint* tex, veil_cache_report* rep, veil_error* err)
{
    memset(rep, 0, sizeof *rep);
    *tex = 0;
    const int sparse = md->grid && md->sparse;
    const int solid = md->solid && md->solid->voxels && md->solid_voxels;
    veil_result r = veil__cache_programs(p, sparse, solid, err);
    if (r != VEIL_OK) return r;
    const size_t cells = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    const int emission = s->emission && md->grid && md->emission;
    float hi[3];
    for (int a = 0; a < 3; ++a) hi[a] = lo[a] + (float)dims[a] * h;

    veil_cache_block b;
    memset(&b, 0, sizeof b);
    for (int a = 0; a < 3; ++a) {
        b.origin[a] = lo[a];
        b.dims[a] = dims[a];
        b.sigma_a[a] = md->scene->medium.sigma_a[a];
        b.sigma_s[a] = md->scene->medium.sigma_s[a];
        b.scale[3] = fmaxf(b.scale[3], b.sigma_a[a] + b.sigma_s[a]);
    }
    b.origin[3] = h;
    b.dims[3] = emission;
    b.sigma_s[3] = md->scene->medium.phase.type == VEIL_PHASE_HG ? md->scene->medium.phase.g : 0.0f;
    const double volume = (double)h * h * h;
    b.scale[2] = (float)(1.0 / volume);
    b.seed[0] = s->seed;

    GLuint buf[5] = {0, 0, 0, 0, 0}; /* sums, cells, emitters, counts, free parts */
    GLuint medium_ubo = 0, env_buf = 0;
    veil_env_table table = {0};
    float* cellv = NULL;
    uint32_t* emit = NULL;
    source src[VEIL_MAX_LIGHTS + 2];
    int n_src = 0;
    r = veil_gl_buffer(NULL, cells * VEIL_CACHE_WORDS * sizeof(uint32_t), GL_DYNAMIC_STORAGE_BIT, "veil cache sums",
                       &buf[0], err);
    if (r == VEIL_OK)
        r = veil_gl_buffer(NULL, cells * 2 * sizeof(float), GL_DYNAMIC_STORAGE_BIT, "veil cache cells", &buf[1], err);
    if (r == VEIL_OK)
        r = veil_gl_buffer(NULL, (4 + VEIL_CACHE_ENERGY_WORDS) * sizeof(uint32_t), GL_DYNAMIC_STORAGE_BIT,
                           "veil cache counts", &buf[3], err);
    if (r == VEIL_OK) { /* each cell's part outside a frame's solid (veil fog): 4^3 points a cell */
        float* fr = malloc(cells * sizeof *fr);
        if (!fr) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for the light cache's cells");
        for (size_t k = 0; fr && k < cells; ++k) {
            fr[k] = 1.0f;
            if (!md->solid || !md->solid->voxels) continue;
            int c[3] = {(int)(k % (size_t)dims[0]), (int)(k / (size_t)dims[0] % (size_t)dims[1]),
                        (int)(k / ((size_t)dims[0] * dims[1]))};
            int apart = 0; /* a cell off the solid's box is free */
            for (int a = 0; a < 3; ++a) {
                float c0 = lo[a] + (float)c[a] * h, s0 = md->solid->origin[a];
                apart |= c0 + h < s0 || c0 > s0 + (float)md->solid->dims[a] * md->solid->voxel;
            }
            if (apart) continue;
            int in = 0;
            for (int q = 0; q < 64; ++q) {
                float x[3];
                for (int a = 0; a < 3; ++a) x[a] = lo[a] + ((float)c[a] + (((q >> (2 * a)) & 3) + 0.5f) / 4.0f) * h;
                in += veil_solid_at(md->solid, x);
            }
            fr[k] = 1.0f - (float)in / 64.0f;
        }
        if (fr) r = veil_gl_buffer(fr, cells * sizeof *fr, 0, "veil cache free parts", &buf[4], err);
        free(fr);
    }
    const int stacked[3] = {dims[0], dims[1], VEIL_CACHE_SLABS * dims[2]};
    if (r == VEIL_OK) r = field_texture(stacked, "veil light cache (fluence, flux)", tex, err);
    if (r != VEIL_OK) goto done;
    static const uint32_t zero = 0;
    glClearNamedBufferData(buf[0], GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glClearNamedBufferData(buf[3], GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    rep->bytes = (double)cells * (VEIL_CACHE_WORDS * 4.0 + 12.0 + 16.0 * VEIL_CACHE_SLABS); /* sums, cells, free parts, the texture */

    /* 1. the cells' majorants (and emission weights) */
    r = veil_gl_buffer(mu, sizeof *mu, 0, "veil cache medium block", &medium_ubo, err);
    if (r != VEIL_OK) goto done;
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MEDIUM, medium_ubo);
    glNamedBufferSubData(p->ubo, 0, sizeof b, &b);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_CACHE, p->ubo);
    if (sparse) veil_ev_sparse_bind(md->sparse);
    glBindTextureUnit(VEIL_TEX_EV, md->grid ? md->ev : 0);
    glBindTextureUnit(VEIL_TEX_EMISSION, emission ? md->emission : 0);
    glBindTextureUnit(VEIL_TEX_SOLID, md->solid_voxels); /* a frame's surfaces absorb photons (scene/solid.h) */
    for (int i = 0; i < 4; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)i, buf[i]);
    glUseProgram(p->bounds[sparse]);
    glDispatchCompute(veil_groups(dims[0], VEIL_CACHE_CELL_GROUP), veil_groups(dims[1], VEIL_CACHE_CELL_GROUP),
                      veil_groups(dims[2], VEIL_CACHE_CELL_GROUP));
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);

    /* 2. the sources: the lights, and the emission by cell */
    for (int l = 0; l < md->light_count && l < VEIL_MAX_LIGHTS; ++l) {
        const veil_gpu_light* gl = &mu->lights[l];
        source* so = &src[n_src];
        memset(so, 0, sizeof *so);
        int ok = (int)gl->position[3] == VEIL_LIGHT_DIRECTIONAL ? sun_source(gl, lo, hi, so) : cone_source(gl, lo, hi, so);
        so->b.source[1] = (uint32_t)l;
        n_src += ok;
    }
    double emit_total = 0.0;
    int emitters = 0;
    cellv = malloc(cells * 2 * sizeof *cellv);
    if (!cellv) {
        r = veil_fail(err, VEIL_ERR_OOM, "out of memory reading the light cache's cells");
        goto done;
    }
    glGetNamedBufferSubData(buf[1], 0, (GLsizeiptr)(cells * 2 * sizeof *cellv), cellv);
    for (size_t k = 0; emission && k < cells; ++k)
        if (cellv[2 * k + 1] > 0.0f) emit_total += cellv[2 * k + 1], ++emitters;

    /* the photons' work, from the majorants: a photon crosses about the grid's longest side, and where
     * the medium is thick it random-walks: about tau^2 real collisions through an optical thickness tau
     * (tau: the largest majorant column along an axis), fewer where it is absorbed first (a / (1 - a)
     * scatterings on average at albedo a); the null collisions about double them */
    double albedo = 0.0;
    for (int c = 0; c < 3; ++c) {
        double st = (double)b.sigma_a[c] + b.sigma_s[c];
        if (st > 0.0) albedo = fmax(albedo, b.sigma_s[c] / st);
    }
    double tau_path = 0.0;
    for (int a = 0; a < 3; ++a) {
        const int u = (a + 1) % 3, v = (a + 2) % 3;
        for (int j = 0; j < dims[u]; ++j)
            for (int i = 0; i < dims[v]; ++i) {
                double col = 0.0;
                for (int t = 0; t < dims[a]; ++t) {
                    int c[3];
                    c[a] = t, c[u] = j, c[v] = i;
                    col += cellv[2 * (((size_t)c[2] * dims[1] + c[1]) * dims[0] + c[0])];
                }
                tau_path = fmax(tau_path, col * b.scale[3] * h);
            }
    }
    int longest = dims[0] > dims[1] ? (dims[0] > dims[2] ? dims[0] : dims[2]) : (dims[1] > dims[2] ? dims[1] : dims[2]);
    double walk = albedo < 1.0 ? fmin(tau_path * tau_path, albedo / (1.0 - albedo)) : tau_path * tau_path;
    double steps = (double)longest + 2.0 * (tau_path + walk);
    double budget = (double)s->photons * VEIL_CACHE_STEPS_PER_PHOTON;
    long long photons = s->photons;
    rep->steps = steps;
    rep->asked = s->photons;
    /* the environment's rest: its photons' table */
    const veil_environment* env = &md->scene->environment;
    int env_src = 0; /* 1: the rest is a source, env_so */
    source env_so;
    memset(&env_so, 0, sizeof env_so);
    if (s->environment && env->present) {
        r = veil_env_rest_table(env, s->env_texels > 0 ? s->env_texels : VEIL_ENV_TABLE_TEXELS, &table, err);
        if (r != VEIL_OK) goto done;
        if (table.n > 0 && env_source(env, &table, lo, hi, &env_so)) {
            r = veil_gl_buffer(table.entries, (size_t)table.n * 8 * sizeof *table.entries, 0,
                               "veil cache environment table", &env_buf, err);
            if (r != VEIL_OK) goto done;
            env_so.table = env_buf;
            env_src = 1;
            veil_env_part_integral(env, 0, rep->env_rest);
        }
        veil_env_table_free(&table);
    }
    if (steps * (double)photons > budget) {
        photons = (long long)(budget / steps);
        if (photons < VEIL_CACHE_MIN_PHOTONS) { /* too thick: no cache, or the environment's rest to its first scattering */
            rep->too_thick = 1;
            if (!env_src) {
                glDeleteTextures(1, tex);
                *tex = 0;
                goto done;
            }
            src[0] = env_so;
            n_src = 1;
            photons = s->photons;
            b.seed[3] = 1;
        }
    }
    rep->cap = rep->too_thick ? VEIL_CACHE_MAX_CUT : (int)fmin(VEIL_CACHE_MAX_CUT, fmax(VEIL_CACHE_MIN_CUT, 8.0 * steps));
    b.seed[2] = (uint32_t)rep->cap;
    if (emitters > 0 && !rep->too_thick) {
        emit = malloc((size_t)emitters * 4 * sizeof *emit);
        if (!emit) {
            r = veil_fail(err, VEIL_ERR_OOM, "out of memory listing the light cache's emitting cells");
            goto done;
        }
        double cdf = 0.0;
        int j = 0;
        for (size_t k = 0; k < cells; ++k) {
            double w = cellv[2 * k + 1];
            if (!(w > 0.0)) continue;
            cdf += w / emit_total;
            float fc = j == emitters - 1 ? 1.0f : (float)cdf, pk = (float)(w / emit_total);
            emit[4 * j] = (uint32_t)k;
            memcpy(&emit[4 * j + 1], &fc, 4);
            memcpy(&emit[4 * j + 2], &pk, 4);
            emit[4 * j + 3] = 0;
            ++j;
        }
        r = veil_gl_buffer(emit, (size_t)emitters * 4 * sizeof *emit, 0, "veil cache emitters", &buf[2], err);
        if (r != VEIL_OK) goto done;
        source* so = &src[n_src++];
        memset(so, 0, sizeof *so);
        so->b.source[0] = VEIL_CACHE_EMISSION;
        /* the weight sums the largest channel over a cell and its ring of voxels: about the cell's
         * emitted radiance per unit volume summed over voxels; its power (for the share) is about
         * 4 pi v^3 that sum (the ring counts some voxels twice: a share, not a result) */
        double v3 = (double)md->grid->voxel * md->grid->voxel * md->grid->voxel;
        so->power = 4.0 * VEIL_PI * v3 * emit_total * VEIL_LUM_G;
        for (int c = 0; c < 3; ++c) so->b.power[c] = (float)(4.0 * VEIL_PI * volume);
        /* a photon's channel c: 4 pi V eps_c(x) / (p_k N) with eps_c(x) <= w_k and p_k = w_k / total */
        so->bound = 4.0 * VEIL_PI * volume * emit_total;
        so->emitters = emitters;
        so->table = buf[2];
    }
    if (env_src && !rep->too_thick) src[n_src++] = env_so; /* the environment's rest, last */

    /* 3. the photons: shared by power (a quarter evenly), at least one a source */
    double total = 0.0;
    for (int j = 0; j < n_src; ++j) total += src[j].power;
    double phi_max = 0.0;
    for (int j = 0; j < n_src; ++j) {
        double share = 0.25 / n_src + 0.75 * (total > 0.0 ? src[j].power / total : 1.0 / n_src);
        src[j].photons = llround((double)photons * share);
        if (src[j].photons < 1) src[j].photons = 1;
        if (src[j].photons > 0xffffffffLL) src[j].photons = 0xffffffffLL;
        phi_max = fmax(phi_max, src[j].bound / (double)src[j].photons);
        rep->photons += src[j].photons;
    }
    rep->sources = n_src;
    /* the largest score: weights summing to at most 3 phi_max over a cell's diagonal, per volume */
    double s_max = 3.0 * phi_max * sqrt(3.0) * h / volume;
    double units = s_max > 0.0 ? ldexp(1.0, VEIL_CACHE_FIXED_BITS) / s_max : 1.0;
    b.scale[0] = (float)units;
    b.scale[1] = (float)(1.0 / units);
    /* the energy account: a photon's channel weight is at most 3 phi_max, 2^VEIL_CACHE_FIXED_BITS units */
    /* (as the shader holds it: a float) */
    const double units_e = (float)(phi_max > 0.0 ? ldexp(1.0, VEIL_CACHE_FIXED_BITS) / (3.0 * phi_max) : 1.0);
    glUseProgram(p->trace[2 * solid + sparse]);
    const int report = veil_progress_wanted();
    long long sent = 0;
    for (int j = 0; j < n_src; ++j) {
        const veil_cache_block* o = &src[j].b;
        b.source[0] = o->source[0];
        b.source[1] = o->source[1];
        b.source[3] = (uint32_t)src[j].photons;
        b.seed[1] = (uint32_t)j;
        b.dims[3] = src[j].emitters;
        for (int c = 0; c < 4; ++c) {
            b.power[c] = (float)(o->power[c] / (double)src[j].photons);
            b.src0[c] = o->src0[c], b.src1[c] = o->src1[c], b.src2[c] = o->src2[c], b.src3[c] = o->src3[c];
        }
        b.power[3] = (float)units_e;
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_CACHE_EMIT, src[j].table);
        for (long long first = 0; first < src[j].photons; first += CACHE_DISPATCH_PHOTONS) {
            long long n = src[j].photons - first < CACHE_DISPATCH_PHOTONS ? src[j].photons - first
                                                                          : CACHE_DISPATCH_PHOTONS;
            b.source[2] = (uint32_t)first;
            glNamedBufferSubData(p->ubo, 0, sizeof b, &b);
            glDispatchCompute(veil_groups((int)n, VEIL_CACHE_GROUP), 1, 1);
            glMemoryBarrier(GL_UNIFORM_BARRIER_BIT);
            sent += n;
            if (report) { /* what is reported is done; a cancel stops between dispatches */
                glFinish();
                veil_progress("light cache, photons", (double)sent, (double)rep->photons);
                if (veil_progress_cancelled() && sent < rep->photons) {
                    r = veil_fail(err, VEIL_ERR_CANCELLED, "cancelled by the progress callback during the light "
                                  "cache (%lld of %lld photons traced)", sent, rep->photons);
                    goto done;
                }
            }
        }
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

    /* 4. the sums turned into the fields */
    glUseProgram(p->resolve);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_CACHE_FREE, buf[4]);
    glBindImageTexture(VEIL_IMAGE_CACHE, *tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(veil_groups(dims[0], VEIL_CACHE_CELL_GROUP), veil_groups(dims[1], VEIL_CACHE_CELL_GROUP),
                      veil_groups(dims[2], VEIL_CACHE_CELL_GROUP));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    uint32_t counts[4 + VEIL_CACHE_ENERGY_WORDS];
    glGetNamedBufferSubData(buf[3], 0, sizeof counts, counts);
    rep->cut = counts[0], rep->clamped = counts[1], rep->misses = counts[2];
    for (int g = 0; g < VEIL_CACHE_ENERGY_GROUPS; ++g)
        for (int q = 0; q < VEIL_CACHE_ENERGY_KINDS; ++q) {
            /* the units of each kind (core/shared.glsl.h) */
            double per_unit = 1.0 / units_e;
            if (q == VEIL_CACHE_ENERGY_COLLISIONS) per_unit *= 65536.0;
            if (q == VEIL_CACHE_ENERGY_TRACK || q == VEIL_CACHE_ENERGY_LATER_TRACK) per_unit *= 65536.0 * sqrt(3.0) * h;
            for (int c = 0; c < 3; ++c) {
                const uint32_t* w = &counts[4 + 2 * (3 * (VEIL_CACHE_ENERGY_KINDS * g + q) + c)];
                double watts = (double)(int64_t)(((uint64_t)w[1] << 32) | w[0]) * per_unit;
                rep->energy_groups[g][q][c] = watts;
                rep->energy[q][c] += watts;
            }
        }

    /* 5. the noise: odd photons against even ones, E (o - e)^2 = Var(o + e) per cell */
    free(cellv);
    cellv = malloc(cells * 4 * VEIL_CACHE_SLABS * sizeof *cellv);
    if (!cellv) {
        r = veil_fail(err, VEIL_ERR_OOM, "out of memory reading the light cache back");
        goto done;
    }
    r = veil_gl_read_texture(*tex, GL_RGBA, cells * 4 * VEIL_CACHE_SLABS, cellv, "the light cache", err);
    if (r != VEIL_OK) goto done;
    double dd = 0.0, tt = 0.0;
    for (size_t k = 0; k < cells; ++k) {
        double t = lum(&cellv[4 * k]), o = cellv[4 * k + 3];
        dd += (2.0 * o - t) * (2.0 * o - t);
        tt += t * t;
    }
    rep->noise = tt > 0.0 ? sqrt(dd / tt) : 0.0;
    memcpy(rep->dims, dims, sizeof rep->dims);
    rep->cell = h;
    r = veil_gl_check("the light cache (volumetric/shaders/cache_*.comp)", err);
done:
    free(cellv);
    free(emit);
    unbind_all();
    if (sparse) veil_ev_sparse_bind(NULL);
    glDeleteBuffers(5, buf);
    glDeleteBuffers(1, &medium_ubo);
    glDeleteBuffers(1, &env_buf);
    veil_env_table_free(&table);
    if (r != VEIL_OK) {
        glDeleteTextures(1, tex);
        *tex = 0;
    }
    return r;
}
