/* veil — small GL helpers shared by the GPU stages: compute programs built
 * from embedded shader files, 3D textures, buffers, and error checks.
 * All functions need a current veil_gl context. Errors name the shader file
 * (with the driver's log) or the object and the GL error.
 */
#ifndef VEIL_GL_UTIL_H
#define VEIL_GL_UTIL_H

#include <epoxy/gl.h>
#include <stddef.h>

#include "../core/clock.h"
#include "../core/result.h"

/* Compiles and links a compute program: "#version 450", VEIL_GLSL, the
 * shared header, then `source`, where a line `//@include NAME` is replaced
 * by the embedded file NAME (gpu/programs.h; includes may nest, at most 8
 * files in all).
 * `file` (e.g. "render/shaders/march.comp") names the shader in errors and
 * in the object label. Stages use veil_gpu_program(); this is for shaders
 * that are not files (tests, benchmarks). */
veil_result veil_gl_compute_program(const char* file, const char* source, GLuint* out, veil_error* err);

/* 3D texture with immutable storage, linear filtering, clamp to edge. */
veil_result veil_gl_texture3d(GLenum internal_format, const int dims[3], const char* label,
                              GLuint* out, veil_error* err);

/* 2D array texture of dims[2] layers of dims[0] x dims[1], otherwise as
 * veil_gl_texture3d: a lookup that reads one layer filters 4 texels, not 8. */
veil_result veil_gl_texture2d_array(GLenum internal_format, const int dims[3], const char* label, GLuint* out,
                                    veil_error* err);

/* Immutable buffer with the given contents (size 0 allowed: 4 bytes). */
veil_result veil_gl_buffer(const void* data, size_t bytes, GLbitfield flags, const char* label,
                           GLuint* out, veil_error* err);

/* Reads level 0 of a texture back as `floats` floats of `format`
 * (GL_RED, GL_RGBA); `what` names it in errors. */
veil_result veil_gl_read_texture(GLuint tex, GLenum format, size_t floats, float* out, const char* what,
                                 veil_error* err);

/* VEIL_ERR_GPU naming `what` when glGetError() reports an error (e.g. an
 * allocation the driver refused); VEIL_OK otherwise. */
veil_result veil_gl_check(const char* what, veil_error* err);

/* Ceiling division for dispatch sizes. */
static inline GLuint veil_groups(int n, int group) { return (GLuint)((n + group - 1) / group); }

#endif
