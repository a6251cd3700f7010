/* veil gpuinfo: the EGL platform and device, GL vendor, renderer, version. */
#include <stdio.h>
#include <stdlib.h>

#include "cli_util.h"
#include "commands.h"
#include "gpu/gl_context.h"

int veil_cmd_gpuinfo(int argc, char** argv)
{
    if (argc > 2) return veil_cli_usage_error("gpuinfo takes no arguments, got '%s'", argv[2]);
    veil_gl* gl = NULL;
    veil_error err = {0};
    veil_result r = veil_gl_create(NULL, &gl, &err);
    if (r != VEIL_OK) {
        fprintf(stderr, "veil: no OpenGL 4.5 context: %s\n", err.msg);
        return EXIT_GPU;
    }
    const veil_gl_info* i = veil_gl_get_info(gl);
    printf("EGL platform:      %s\n", i->platform);
    printf("EGL device:        %s (%s)\n", i->device, i->hardware ? "hardware" : "software");
    printf("GL vendor:         %s\n", i->vendor);
    printf("GL renderer:       %s\n", i->renderer);
    printf("GL version:        %s\n", i->version);
    printf("max 3D texture:    %d\n", i->max_3d_texture_size);
    veil_gl_destroy(gl);
    return EXIT_OK;
}

