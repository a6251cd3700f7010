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
#define VEIL__MAX_INCLUDES 8 /* files per program, nesting included */

/* The text being assembled: the shader with its includes expanded in
 * place, each followed by a #line that resumes the file it came from. */
typedef struct veil__text {
    char* buf;
    size_t len, cap;
    const char* names[VEIL__MAX_INCLUDES + 2]; /* source string k of the driver's log */
    int count;
} veil__text;

static int text_put(veil__text* t, const char* s, size_t n)
{
    if (t->len + n + 1 > t->cap) {
        size_t cap = 2 * (t->len + n + 1);
        char* b = realloc(t->buf, cap);
        if (!b) return 0;
        t->buf = b, t->cap = cap;
    }
    memcpy(t->buf + t->len, s, n);
    t->len += n;
    t->buf[t->len] = 0;
    return 1;
}

/* Appends `source` (source string number `id`), expanding its includes. */
static veil_result expand(veil__text* t, const char* file, const char* source, int id, int depth, veil_error* err)
{
    if (depth > VEIL__MAX_INCLUDES)
        return veil_fail(err, VEIL_ERR_SHADER, "%s: includes nested deeper than %d", file, VEIL__MAX_INCLUDES);
    char line[64];
    int n = snprintf(line, sizeof line, "\n#line 1 %d\n", id);
    if (!text_put(t, line, (size_t)n)) return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory", file);
    int lineno = 1;
    for (const char* p = source; *p;) {
        const char* eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) + 1 : strlen(p);
        size_t mark = strlen(VEIL__INCLUDE_MARK);
        if (len > mark && !strncmp(p, VEIL__INCLUDE_MARK, mark)) {
            const char* name = p + mark;
            size_t name_len = len - mark - (eol ? 1 : 0);
            const char* header = veil_shader_source(name, name_len);
            if (!header)
                return veil_fail(err, VEIL_ERR_SHADER, "%s: unknown include '%.*s'", file, (int)name_len, name);
            if (t->count == VEIL__MAX_INCLUDES + 2)
                return veil_fail(err, VEIL_ERR_SHADER, "%s: more than %d includes", file, VEIL__MAX_INCLUDES);
            int sub = t->count;
            for (int i = 0; i < veil_shader_file_count; ++i)
                if (veil_shader_files[i].source == header) t->names[t->count++] = veil_shader_files[i].path;
            veil_result r = expand(t, file, header, sub, depth + 1, err);
            if (r != VEIL_OK) return r;
            n = snprintf(line, sizeof line, "\n#line %d %d\n", lineno + 1, id);
            if (!text_put(t, line, (size_t)n)) return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory", file);
        } else if (!text_put(t, p, len)) {
            return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory", file);
        }
        p += len;
        ++lineno;
    }
    return VEIL_OK;
}

veil_result veil_gl_compute_program(const char* file, const char* source, GLuint* out, veil_error* err)
{
    *out = 0;
    /* Source strings: 0 = core/shared.glsl.h, 1 = the shader file, 2.. = its
     * includes in the order met; #line keeps each one's own line numbers in logs. */
    const char* parts[3] = {"#version 450 core\n#define VEIL_GLSL 1\n#line 1 0\n", veil_shader_source("core/shared.glsl.h", 0),
                            NULL};
    veil__text t = {.names = {"core/shared.glsl.h", file}, .count = 2};
    veil_result res = expand(&t, file, source, 1, 0, err);
    if (res != VEIL_OK) {
        free(t.buf);
        return res;
    }
    parts[2] = t.buf;
    int n = 3;
    GLuint sh = glCreateShader(GL_COMPUTE_SHADER);
    glShaderSource(sh, n, parts, NULL);
    glCompileShader(sh);
    free(t.buf);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char* log = info_log(sh, 0);
        char names[512] = "";
        for (int i = 0; i < t.count; ++i) {
            size_t len = strlen(names);
            snprintf(names + len, sizeof names - len, "%s%d %s", i ? ", " : "", i, t.names[i]);
        }
        veil_fail(err, VEIL_ERR_SHADER, "%s: compile failed (the log's source numbers: %s):\n%s", file, names,
                  log ? log : "(no log)");
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

/* Immutable storage for a 3D or 2D array texture of dims (its limits
 * checked by the caller), linear filtering, clamped to the edge. */
static veil_result texture_storage(GLenum target, GLenum internal_format, const int dims[3], const char* label,
                                   GLuint* out, veil_error* err)
{
    glCreateTextures(target, 1, out);
    glTextureStorage3D(*out, 1, internal_format, dims[0], dims[1], dims[2]);
    glTextureParameteri(*out, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(*out, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(*out, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(*out, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    if (target == GL_TEXTURE_3D) glTextureParameteri(*out, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    glObjectLabel(GL_TEXTURE, *out, -1, label);
    veil_result r = veil_gl_check(label, err);
    if (r != VEIL_OK) {
        glDeleteTextures(1, out);
        *out = 0;
    }
    return r;
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
    return texture_storage(GL_TEXTURE_3D, internal_format, dims, label, out, err);
}

veil_result veil_gl_texture2d_array(GLenum internal_format, const int dims[3], const char* label, GLuint* out,
                                    veil_error* err)
{
    GLint max2d = 0, layers = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max2d);
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &layers);
    if (dims[0] < 1 || dims[1] < 1 || dims[2] < 1 || dims[0] > max2d || dims[1] > max2d || dims[2] > layers)
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: %dx%d texels, %d layers exceeds the GL limits (%d a side, %d layers)",
                         label, dims[0], dims[1], dims[2], max2d, layers);
    return texture_storage(GL_TEXTURE_2D_ARRAY, internal_format, dims, label, out, err);
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
