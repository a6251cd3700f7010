#define _POSIX_C_SOURCE 200809L
#include "gl_util.h"
#include "programs.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* gl_error_name(GLenum e)
{
    switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    default: return "GL error";
    }
}

veil_result veil_gl_check(const char* what, veil_error* err)
{
    GLenum e = glGetError();
    if (e == GL_NO_ERROR) return VEIL_OK;
    while (glGetError() != GL_NO_ERROR) {
    }
    return veil_fail(err, VEIL_ERR_GPU, "%s: %s (0x%04x)", what, gl_error_name(e), (unsigned)e);
}

static char* info_log(GLuint obj, int is_program)
{
    GLint len = 0;
    if (is_program) glGetProgramiv(obj, GL_INFO_LOG_LENGTH, &len);
    else glGetShaderiv(obj, GL_INFO_LOG_LENGTH, &len);
    char* log = calloc((size_t)len + 1, 1);
    if (!log) return NULL;
    if (is_program) glGetProgramInfoLog(obj, len, NULL, log);
    else glGetShaderInfoLog(obj, len, NULL, log);
    return log;
}

/* The shader line that pulls in an embedded header (GLSL has no #include). */
#define VEIL__INCLUDE_MARK "//@include "

veil_result veil_gl_compute_program(const char* file, const char* source, GLuint* out, veil_error* err)
{
    *out = 0;
    /* Source strings: 0 = core/shared.glsl.h, 1 = the shader file, 2 = an
     * included header; #line keeps each one's own line numbers in logs. */
    const char* parts[8] = {"#version 450 core\n#define VEIL_GLSL 1\n#line 1 0\n", veil_shader_source("core/shared.glsl.h", 0),
                            "\n#line 1 1\n"};
    GLint lens[8] = {-1, -1, -1};
    int n = 3;
    char resume[64] = "";
    const char* mark = strstr(source, VEIL__INCLUDE_MARK);
    if (mark) {
        const char* name = mark + strlen(VEIL__INCLUDE_MARK);
        const char* eol = strchr(name, '\n');
        size_t name_len = eol ? (size_t)(eol - name) : strlen(name);
        const char* header = veil_shader_source(name, name_len);
        if (!header)
            return veil_fail(err, VEIL_ERR_SHADER, "%s: unknown include '%.*s'", file, (int)name_len, name);
        int line = 1;
        for (const char* c = source; c < mark; ++c) line += *c == '\n';
        snprintf(resume, sizeof resume, "\n#line %d 1\n", line + 1);
        parts[n] = source;
        lens[n++] = (GLint)(mark - source);
        parts[n] = "\n#line 1 2\n";
        lens[n++] = -1;
        parts[n] = header;
        lens[n++] = -1;
        parts[n] = resume;
        lens[n++] = -1;
        parts[n] = eol ? eol : "";
        lens[n++] = -1;
    } else {
        parts[n] = source;
        lens[n++] = -1;
    }
    GLuint sh = glCreateShader(GL_COMPUTE_SHADER);
    glShaderSource(sh, n, parts, lens);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char* log = info_log(sh, 0);
        veil_fail(err, VEIL_ERR_SHADER,
                  "%s: compile failed (in the log, source 1 is this file, 0 core/shared.glsl.h, 2 its include):\n%s",
                  file, log ? log : "(no log)");
        free(log);
        glDeleteShader(sh);
        return VEIL_ERR_SHADER;
    }
    GLuint prog = glCreateProgram();
    glAttachShader(prog, sh);
    glLinkProgram(prog);
    glDeleteShader(sh);
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char* log = info_log(prog, 1);
        veil_fail(err, VEIL_ERR_SHADER, "%s: link failed:\n%s", file, log ? log : "(no log)");
        free(log);
        glDeleteProgram(prog);
        return VEIL_ERR_SHADER;
    }
    glObjectLabel(GL_PROGRAM, prog, -1, file);
    *out = prog;
    return VEIL_OK;
}

veil_result veil_gl_texture3d(GLenum internal_format, const int dims[3], const char* label,
                              GLuint* out, veil_error* err)
{
    GLint max3d = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    for (int a = 0; a < 3; ++a)
        if (dims[a] < 1 || dims[a] > max3d)
            return veil_fail(err, VEIL_ERR_LIMIT, "%s: %dx%dx%d voxels exceeds the GL limit of %d per side",
                             label, dims[0], dims[1], dims[2], max3d);
    glCreateTextures(GL_TEXTURE_3D, 1, out);
    glTextureStorage3D(*out, 1, internal_format, dims[0], dims[1], dims[2]);
    glTextureParameteri(*out, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(*out, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(*out, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(*out, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(*out, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    glObjectLabel(GL_TEXTURE, *out, -1, label);
    veil_result r = veil_gl_check(label, err);
    if (r != VEIL_OK) {
        glDeleteTextures(1, out);
        *out = 0;
    }
    return r;
}

veil_result veil_gl_buffer(const void* data, size_t bytes, GLbitfield flags, const char* label,
                           GLuint* out, veil_error* err)
{
    static const uint32_t zero = 0;
    glCreateBuffers(1, out);
    glNamedBufferStorage(*out, (GLsizeiptr)(bytes ? bytes : sizeof zero), bytes ? data : &zero, flags);
    glObjectLabel(GL_BUFFER, *out, -1, label);
    veil_result r = veil_gl_check(label, err);
    if (r != VEIL_OK) {
        glDeleteBuffers(1, out);
        *out = 0;
    }
    return r;
}

veil_result veil_gl_read_texture(GLuint tex, GLenum format, size_t floats, float* out, const char* what,
                                 veil_error* err)
{
    size_t bytes = floats * sizeof(float);
    if (bytes > (size_t)INT32_MAX)
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: %zu bytes is too large to read back", what, bytes);
    glGetTextureImage(tex, 0, format, GL_FLOAT, (GLsizei)bytes, out);
    return veil_gl_check(what, err);
}
