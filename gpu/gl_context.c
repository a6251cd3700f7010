#define _POSIX_C_SOURCE 200809L
#include "gl_context.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef EGL_DEVICE_EXT
#define EGL_DEVICE_EXT 0x322C
#endif
#ifndef EGL_DRM_DEVICE_FILE_EXT
#define EGL_DRM_DEVICE_FILE_EXT 0x3233
#endif
#ifndef EGL_DRM_RENDER_NODE_FILE_EXT
#define EGL_DRM_RENDER_NODE_FILE_EXT 0x3377
#endif

/* EGL hands every context of one device the same EGLDisplay, and
 * eglTerminate on it ends them all: a second veil_gl made and destroyed on
 * the same device left the first one rendering NaN (issue 22). Displays are
 * therefore counted, and terminated when their last veil_gl goes. */
#define VEIL__MAX_DISPLAYS 16
static struct {
    EGLDisplay display;
    int users;
} g_displays[VEIL__MAX_DISPLAYS];
static pthread_mutex_t g_displays_lock = PTHREAD_MUTEX_INITIALIZER;

/* eglInitialize, counted; 0 when it fails or too many displays are live. */
static int display_acquire(EGLDisplay d)
{
    pthread_mutex_lock(&g_displays_lock);
    int slot = -1, ok = 0;
    for (int i = 0; i < VEIL__MAX_DISPLAYS && slot < 0; ++i)
        if (g_displays[i].users > 0 && g_displays[i].display == d) slot = i;
    for (int i = 0; i < VEIL__MAX_DISPLAYS && slot < 0; ++i)
        if (g_displays[i].users == 0) slot = i;
    EGLint major, minor;
    if (slot >= 0 && (g_displays[slot].users > 0 || eglInitialize(d, &major, &minor))) {
        g_displays[slot].display = d;
        g_displays[slot].users++;
        ok = 1;
    }
    pthread_mutex_unlock(&g_displays_lock);
    return ok;
}

/* The counterpart of display_acquire: eglTerminate once no veil_gl uses d. */
static void display_release(EGLDisplay d)
{
    pthread_mutex_lock(&g_displays_lock);
    for (int i = 0; i < VEIL__MAX_DISPLAYS; ++i) {
        if (g_displays[i].users > 0 && g_displays[i].display == d) {
            if (--g_displays[i].users == 0) eglTerminate(d);
            break;
        }
    }
    pthread_mutex_unlock(&g_displays_lock);
}

/* Most devices a machine could expose that we look at. */
#define VEIL__MAX_EGL_DEVICES 16

struct veil_gl {
    EGLDisplay display;
    EGLContext context;
    veil_gl_info info;
    char device[256];
    char vendor[128], renderer[256], version[128];
};

static int has_ext(const char* list, const char* name)
{
    if (!list) return 0;
    size_t n = strlen(name);
    for (const char* p = list; (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return 1;
    return 0;
}

static const char* egl_error_name(EGLint e)
{
    switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    default: return "unknown EGL error";
    }
}

static veil_result egl_fail(veil_error* err, const char* call, const char* what)
{
    EGLint e = eglGetError();
    return veil_fail(err, VEIL_ERR_GPU, "%s failed (%s, 0x%04x)%s%s", call, egl_error_name(e),
                     (unsigned)e, what ? ": " : "", what ? what : "");
}

/* Makes a 4.5 core context on an initialised display. */
static veil_result make_context(veil_gl* gl, const veil_gl_desc* desc, veil_error* err)
{
    const char* exts = eglQueryString(gl->display, EGL_EXTENSIONS);
    if (!has_ext(exts, "EGL_KHR_no_config_context") && !has_ext(exts, "EGL_MESA_configless_context"))
        return veil_fail(err, VEIL_ERR_GPU, "EGL display lacks EGL_KHR_no_config_context");
    if (!has_ext(exts, "EGL_KHR_surfaceless_context"))
        return veil_fail(err, VEIL_ERR_GPU, "EGL display lacks EGL_KHR_surfaceless_context");
    if (!eglBindAPI(EGL_OPENGL_API)) return egl_fail(err, "eglBindAPI(EGL_OPENGL_API)", NULL);
    const EGLint attrs[] = {
        EGL_CONTEXT_MAJOR_VERSION, 4,
        EGL_CONTEXT_MINOR_VERSION, 5,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL_CONTEXT_OPENGL_DEBUG, desc->debug ? EGL_TRUE : EGL_FALSE,
        EGL_NONE,
    };
    gl->context = eglCreateContext(gl->display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attrs);
    if (gl->context == EGL_NO_CONTEXT) return egl_fail(err, "eglCreateContext(OpenGL 4.5 core)", NULL);
    if (!eglMakeCurrent(gl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->context))
        return egl_fail(err, "eglMakeCurrent(no surface)", NULL);
    return VEIL_OK;
}

static int device_is_software(EGLDeviceEXT dev)
{
    const char* dexts = eglQueryDeviceStringEXT(dev, EGL_EXTENSIONS);
    return has_ext(dexts, "EGL_MESA_device_software");
}

static void describe_device(veil_gl* gl, EGLDeviceEXT dev)
{
    const char* node = NULL;
    const char* dexts = eglQueryDeviceStringEXT(dev, EGL_EXTENSIONS);
    if (has_ext(dexts, "EGL_EXT_device_drm_render_node"))
        node = eglQueryDeviceStringEXT(dev, EGL_DRM_RENDER_NODE_FILE_EXT);
    if (!node && has_ext(dexts, "EGL_EXT_device_drm"))
        node = eglQueryDeviceStringEXT(dev, EGL_DRM_DEVICE_FILE_EXT);
    snprintf(gl->device, sizeof gl->device, "%s", node ? node : (device_is_software(dev) ? "software" : "-"));
}

/* Tries the device platform; *tried says whether it was available at all. */
static veil_result try_device_platform(veil_gl* gl, const veil_gl_desc* desc, int software_only,
                                       veil_error* err)
{
    EGLDeviceEXT devs[VEIL__MAX_EGL_DEVICES];
    EGLint n = 0;
    if (!eglQueryDevicesEXT(VEIL__MAX_EGL_DEVICES, devs, &n) || n <= 0)
        return egl_fail(err, "eglQueryDevicesEXT", "no EGL devices");
    veil_result last = veil_fail(err, VEIL_ERR_GPU, "no usable EGL device among %d", (int)n);
    /* two passes: hardware devices first, then software ones */
    for (int pass = software_only ? 1 : 0; pass < 2; ++pass) {
        for (EGLint i = 0; i < n; ++i) {
            int sw = device_is_software(devs[i]);
            if (sw != (pass == 1)) continue;
            gl->display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devs[i], NULL);
            if (gl->display == EGL_NO_DISPLAY) {
                last = egl_fail(err, "eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT)", NULL);
                continue;
            }
            if (!display_acquire(gl->display)) {
                last = egl_fail(err, "eglInitialize(device display)", NULL);
                gl->display = EGL_NO_DISPLAY;
                continue;
            }
            last = make_context(gl, desc, err);
            if (last == VEIL_OK) {
                gl->info.platform = "EGL_EXT_platform_device";
                gl->info.hardware = !sw;
                describe_device(gl, devs[i]);
                return VEIL_OK;
            }
            display_release(gl->display);
            gl->display = EGL_NO_DISPLAY;
        }
    }
    return last;
}

static veil_result try_surfaceless(veil_gl* gl, const veil_gl_desc* desc, veil_error* err)
{
    gl->display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (gl->display == EGL_NO_DISPLAY)
        return egl_fail(err, "eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)", NULL);
    if (!display_acquire(gl->display)) {
        gl->display = EGL_NO_DISPLAY;
        return egl_fail(err, "eglInitialize(surfaceless display)", NULL);
    }
    veil_result r = make_context(gl, desc, err);
    if (r != VEIL_OK) {
        display_release(gl->display);
        gl->display = EGL_NO_DISPLAY;
        return r;
    }
    gl->info.platform = "EGL_MESA_platform_surfaceless";
    snprintf(gl->device, sizeof gl->device, "-");
    return VEIL_OK;
}

static void APIENTRY debug_callback(GLenum source, GLenum type, GLuint id, GLenum severity,
                                    GLsizei length, const GLchar* message, const void* user)
{
    if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
    fprintf(stderr, "veil: GL debug: %s\n", message);
}

#ifndef GL_GPU_MEMORY_INFO_TOTAL_AVAILABLE_MEMORY_NVX
#define GL_GPU_MEMORY_INFO_TOTAL_AVAILABLE_MEMORY_NVX 0x9048
#endif

static unsigned long long memory_budget(void)
{
    double bytes = 0.0;
    if (epoxy_has_gl_extension("GL_NVX_gpu_memory_info")) {
        GLint kib = 0;
        glGetIntegerv(GL_GPU_MEMORY_INFO_TOTAL_AVAILABLE_MEMORY_NVX, &kib);
        bytes = (double)kib * 1024.0;
    }
    if (!(bytes > 0.0)) {
        long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
        bytes = pages > 0 && page > 0 ? (double)pages * (double)page : 1024.0 * 1024.0 * 1024.0;
    }
    return (unsigned long long)(bytes * VEIL_GPU_MEMORY_FRACTION);
}

veil_result veil_gl_create(const veil_gl_desc* desc, veil_gl** out, veil_error* err)
{
    *out = NULL;
    veil_gl_desc d = desc ? *desc : (veil_gl_desc){0};
    const char* env = getenv("VEIL_DEVICE");
    int software_only = d.force_software || (env && strcmp(env, "software") == 0);

    veil_gl* gl = calloc(1, sizeof *gl);
    if (!gl) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the GL context");
    gl->display = EGL_NO_DISPLAY;
    gl->context = EGL_NO_CONTEXT;

    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client) {
        free(gl);
        return egl_fail(err, "eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS)",
                        "no EGL client extensions (is libegl1 with a Mesa or NVIDIA vendor library installed?)");
    }
    veil_result r = VEIL_ERR_GPU;
    veil_error first = {0};
    if (has_ext(client, "EGL_EXT_platform_device") && has_ext(client, "EGL_EXT_device_enumeration"))
        r = try_device_platform(gl, &d, software_only, &first);
    else
        veil_fail(&first, VEIL_ERR_GPU, "eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS) does not offer "
                                        "EGL_EXT_platform_device with EGL_EXT_device_enumeration");
    if (r != VEIL_OK) {
        if (has_ext(client, "EGL_MESA_platform_surfaceless")) {
            r = try_surfaceless(gl, &d, err);
            if (r != VEIL_OK && err) {
                char tmp[VEIL_ERROR_MAX];
                snprintf(tmp, sizeof tmp, "%.1000s; fallback: %.1000s", first.msg, err->msg);
                memcpy(err->msg, tmp, sizeof tmp);
            }
        } else {
            r = veil_fail(err, VEIL_ERR_GPU,
                          "%.1000s; and eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS) does not offer "
                          "EGL_MESA_platform_surfaceless (client extensions: %.600s; is an EGL vendor "
                          "library such as libegl-mesa0 installed?)",
                          first.msg, client);
        }
    }
    if (r != VEIL_OK) {
        free(gl);
        return r;
    }
    if (epoxy_gl_version() < 45) {
        veil_fail(err, VEIL_ERR_GPU, "OpenGL 4.5 needed, context reports %d.%d",
                  epoxy_gl_version() / 10, epoxy_gl_version() % 10);
        veil_gl_destroy(gl);
        return VEIL_ERR_GPU;
    }
    snprintf(gl->vendor, sizeof gl->vendor, "%s", (const char*)glGetString(GL_VENDOR));
    snprintf(gl->renderer, sizeof gl->renderer, "%s", (const char*)glGetString(GL_RENDERER));
    snprintf(gl->version, sizeof gl->version, "%s", (const char*)glGetString(GL_VERSION));
    gl->info.vendor = gl->vendor;
    gl->info.renderer = gl->renderer;
    gl->info.version = gl->version;
    gl->info.device = gl->device;
    if (strstr(gl->renderer, "llvmpipe") || strstr(gl->renderer, "softpipe")) gl->info.hardware = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &gl->info.max_3d_texture_size);
    glGetIntegerv(GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS, &gl->info.max_compute_work_group_invocations);
    gl->info.memory_budget = memory_budget();
    if (d.debug) {
        glEnable(GL_DEBUG_OUTPUT);
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        glDebugMessageCallback(debug_callback, NULL);
    }
    *out = gl;
    return VEIL_OK;
}

void veil_gl_destroy(veil_gl* gl)
{
    if (!gl) return;
    if (gl->display != EGL_NO_DISPLAY) {
        /* release the thread's context only when it is this one: another veil_gl may be current */
        if (eglGetCurrentContext() == gl->context)
            eglMakeCurrent(gl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (gl->context != EGL_NO_CONTEXT) eglDestroyContext(gl->display, gl->context);
        display_release(gl->display);
    }
    free(gl);
}

veil_result veil_gl_make_current(const veil_gl* gl, veil_error* err)
{
    if (eglGetCurrentContext() == gl->context) return VEIL_OK;
    if (!eglMakeCurrent(gl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->context))
        return egl_fail(err, "eglMakeCurrent(no surface)",
                        "the veil_context could not be made current on this thread (is it current on another?)");
    return VEIL_OK;
}

const veil_gl_info* veil_gl_get_info(const veil_gl* gl) { return &gl->info; }
