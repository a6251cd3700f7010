#include "pass_run.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "gl_util.h"

/* The first run's capacity (passes): a sun's slices or a point light's
 * shells on a 64^3 grid fit. */
#define VEIL_PASS_RUN_FIRST_CAP 256

void veil_pass_run_init(veil_pass_run* run, size_t size, const char* label)
{
    memset(run, 0, sizeof *run);
    run->size = size;
    run->label = label;
}

void veil_pass_run_free(veil_pass_run* run)
{
    glDeleteBuffers(1, &run->buffer);
    free(run->cpu);
    free(run->groups);
    veil_pass_run_init(run, run->size, run->label);
}

veil_result veil_pass_run_add(veil_pass_run* run, GLuint gx, GLuint gy, GLuint gz, void** block, veil_error* err)
{
    *block = NULL;
    if (!run->stride) {
        GLint align = 0;
        glGetIntegerv(GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT, &align);
        size_t a = align > 0 ? (size_t)align : 256; /* 256: the most GL 4.5 allows */
        run->stride = (run->size + a - 1) / a * a;
    }
    if (run->count == run->cap) {
        size_t cap = run->cap ? 2 * run->cap : VEIL_PASS_RUN_FIRST_CAP;
        if (cap > SIZE_MAX / run->stride || cap > SIZE_MAX / sizeof *run->groups)
            return veil_fail(err, VEIL_ERR_LIMIT, "too many passes (%s)", run->label);
        unsigned char* cpu = realloc(run->cpu, cap * run->stride);
        if (cpu) run->cpu = cpu;
        GLuint(*groups)[3] = cpu ? realloc(run->groups, cap * sizeof *run->groups) : NULL;
        if (groups) run->groups = groups;
        if (!cpu || !groups) return veil_fail(err, VEIL_ERR_OOM, "out of memory for %zu passes (%s)", cap, run->label);
        run->cap = cap;
    }
    run->groups[run->count][0] = gx, run->groups[run->count][1] = gy, run->groups[run->count][2] = gz;
    unsigned char* b = run->cpu + run->count++ * run->stride;
    memset(b, 0, run->stride);
    *block = b;
    return VEIL_OK;
}

veil_result veil_pass_run_upload(veil_pass_run* run, veil_error* err)
{
    size_t bytes = run->count * run->stride;
    if (bytes == 0) return VEIL_OK;
    if (bytes > run->buffer_bytes) {
        size_t grow = bytes > 2 * run->buffer_bytes ? bytes : 2 * run->buffer_bytes;
        glDeleteBuffers(1, &run->buffer);
        run->buffer = 0;
        run->buffer_bytes = 0;
        veil_result r = veil_gl_buffer(NULL, grow, GL_DYNAMIC_STORAGE_BIT, run->label, &run->buffer, err);
        if (r != VEIL_OK) return r;
        run->buffer_bytes = grow;
    }
    glNamedBufferSubData(run->buffer, 0, (GLsizeiptr)bytes, run->cpu);
    return VEIL_OK;
}

void veil_pass_run_dispatch(const veil_pass_run* run, GLuint binding, size_t k)
{
    glBindBufferRange(GL_UNIFORM_BUFFER, binding, run->buffer, (GLintptr)(k * run->stride), (GLsizeiptr)run->size);
    glDispatchCompute(run->groups[k][0], run->groups[k][1], run->groups[k][2]);
}
