/* veil — headless OpenGL 4.5 core context through EGL, no window system.
 *
 * Order: EGL_EXT_platform_device, preferring a hardware device (one that
 * does not advertise EGL_MESA_device_software), then the software device,
 * then EGL_MESA_platform_surfaceless. A 4.5 core context with
 * EGL_NO_CONFIG_KHR and no surface is made current on the calling thread.
 * VEIL_DEVICE=software (environment) skips hardware devices.
 *
 * On failure the message names the EGL call that failed and its error code.
 */
#ifndef VEIL_GL_CONTEXT_H
#define VEIL_GL_CONTEXT_H

#include "../core/result.h"

typedef struct veil_gl veil_gl;

typedef struct veil_gl_desc {
    int force_software; /* 0: honour VEIL_DEVICE; 1: software device only */
    int debug;          /* 1: debug context with a synchronous KHR_debug callback */
} veil_gl_desc;

typedef struct veil_gl_info {
    const char* platform;  /* "EGL_EXT_platform_device" or "EGL_MESA_platform_surfaceless" */
    const char* device;    /* DRM render node / device extensions, or "-" */
    int hardware;          /* 1 when the device is not a software rasteriser */
    const char* vendor, *renderer, *version;
    int max_3d_texture_size;
    int max_compute_work_group_invocations;
    /* Bytes of textures veil allows itself: VEIL_GPU_MEMORY_FRACTION of the
     * dedicated memory a GPU reports (GL_NVX_gpu_memory_info), else of the
     * machine's physical memory (a software rasteriser's textures live there). */
    unsigned long long memory_budget;
} veil_gl_info;

#define VEIL_GPU_MEMORY_FRACTION 0.5

veil_result veil_gl_create(const veil_gl_desc* desc, veil_gl** out, veil_error* err);
void veil_gl_destroy(veil_gl* gl); /* accepts NULL */
/* Makes gl's context current on the calling thread (a no-op when it is):
 * several veil_gl may live on one thread, each made current before use.
 * VEIL_ERR_GPU when it is current on another thread. */
veil_result veil_gl_make_current(const veil_gl* gl, veil_error* err);
const veil_gl_info* veil_gl_get_info(const veil_gl* gl);

#endif
