/* veil — a run of compute passes, each a dispatch with its own std140
 * block: the blocks are filled on the CPU, uploaded to one uniform buffer
 * at once, then each pass binds its block (glBindBufferRange) and
 * dispatches. Writing a uniform buffer between two dispatches that read
 * it asks the driver to keep the old contents for the dispatch still
 * pending (a copy or a wait, as the driver chooses); binding another range
 * of a buffer written before the run asks for nothing. (On llvmpipe both
 * cost the same: the ordered optical-depth sweeps, a few hundred passes a
 * light, run as fast either way.)
 *
 * Blocks lie `stride` bytes apart: the block's size rounded up to
 * GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT. A run owns its buffer (labelled) and
 * its CPU copy, is reused (clear, add, upload, dispatch) and grows as
 * needed. Needs a current GL context from the first add on.
 */
#ifndef VEIL_PASS_RUN_H
#define VEIL_PASS_RUN_H

#include <epoxy/gl.h>
#include <stddef.h>

#include "../core/result.h"

typedef struct veil_pass_run {
    GLuint buffer;        /* 0 until the first upload */
    size_t buffer_bytes;  /* its size */
    size_t size, stride;  /* a block's bytes; bytes from one block to the next (0 until the first add) */
    unsigned char* cpu;   /* the blocks, stride apart */
    GLuint (*groups)[3];  /* each pass's work groups */
    size_t count, cap;    /* passes in the run; room for cap of them on the CPU */
    const char* label;    /* the buffer's label (a string literal: kept, not copied) */
} veil_pass_run;

/* An empty run of passes whose blocks have `size` bytes; no GL object yet. */
void veil_pass_run_init(veil_pass_run* run, size_t size, const char* label);
/* Frees the buffer and the CPU copy; the run is empty, as after init. */
void veil_pass_run_free(veil_pass_run* run);

/* Empties the run (keeps its memory). */
static inline void veil_pass_run_clear(veil_pass_run* run) { run->count = 0; }

/* A new pass of gx * gy * gz work groups at the end of the run; *block:
 * its block, zeroed, to be filled before the upload (valid until the next
 * add). VEIL_ERR_OOM when memory runs out. */
veil_result veil_pass_run_add(veil_pass_run* run, GLuint gx, GLuint gy, GLuint gz, void** block, veil_error* err);

/* Uploads the blocks of the run (growing the buffer when they do not fit). */
veil_result veil_pass_run_upload(veil_pass_run* run, veil_error* err);

/* Pass k of the uploaded run: binds its block at uniform buffer binding
 * `binding` and dispatches its work groups with the program in use. The
 * caller puts the barriers between passes and unbinds the block at the end
 * (glBindBufferBase(GL_UNIFORM_BUFFER, binding, 0)). */
void veil_pass_run_dispatch(const veil_pass_run* run, GLuint binding, size_t k);

#endif
