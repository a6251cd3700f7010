/* veil — small GL helpers shared by the GPU stages: compute programs built
 * from embedded shader files, 3D textures, buffers, and error checks.
 * All functions need a current veil_gl context. Errors name the shader file
 * (with the driver's log) or the object and the GL error.
 */
#ifndef VEIL_GL_UTIL_H
#define VEIL_GL_UTIL_H

#include <epoxy/gl.h>
#include <stddef.h>

#include "../core/result.h"

/* Embedded sources (generated at build time from the files of the same name). */
extern const char veil_shader_shared_glsl_h[];
extern const char veil_shader_inject_rbf_comp[];
extern const char veil_shader_propagate_jacobi_comp[];
extern const char veil_shader_propagate_sweep_comp[];
extern const char veil_shader_opv_schemes_glsl_h[];
extern const char veil_shader_march_comp[];
extern const char veil_shader_occupancy_comp[];

/* Compiles and links a compute program: "#version 450", VEIL_GLSL, the
 * shared header, then `source`, where a line `//@include NAME` is replaced
 * by the embedded header NAME (only propagate/opv_schemes.glsl.h). `file` (e.g. "render/shaders/march.comp")
 * names the shader in errors and in the object label. */
veil_result veil_gl_compute_program(const char* file, const char* source, GLuint* out, veil_error* err);

/* 3D texture with immutable storage, linear filtering, clamp to edge. */
veil_result veil_gl_texture3d(GLenum internal_format, const int dims[3], const char* label,
                              GLuint* out, veil_error* err);

/* Immutable buffer with the given contents (size 0 allowed: 4 bytes). */
veil_result veil_gl_buffer(const void* data, size_t bytes, GLbitfield flags, const char* label,
                           GLuint* out, veil_error* err);

/* VEIL_ERR_GPU naming `what` when glGetError() reports an error (e.g. an
 * allocation the driver refused); VEIL_OK otherwise. */
veil_result veil_gl_check(const char* what, veil_error* err);

/* Ceiling division for dispatch sizes. */
static inline GLuint veil_groups(int n, int group) { return (GLuint)((n + group - 1) / group); }

/* Monotonic wall clock in milliseconds. */
double veil_now_ms(void);

#endif
