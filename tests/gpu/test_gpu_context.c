/* A headless GL 4.5 context exists (skipped where none can be made, failed
 * under CI), reports sane limits, and every embedded shader compiles. A
 * broken shader names its file. */
#include <string.h>

#include "support/check.h"
#include "gpu/gl_context.h"
#include "gpu/gl_util.h"
#include "frame/renderer.h"

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    const veil_gl_info* info = veil_gl_get_info(gl);
    printf("%s on %s: %s / %s / %s\n", info->platform, info->device, info->vendor, info->renderer, info->version);
    CHECK(info->max_3d_texture_size >= 256, "max 3D texture %d", info->max_3d_texture_size);
    CHECK(strncmp(info->version, "4.", 2) == 0, "version %s", info->version);

    veil_renderer* r = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "shaders failed: %s", err.msg);
    veil_renderer_destroy(r);

    GLuint prog = 0;
    veil_result res = veil_gl_compute_program("tests/broken.comp", "layout(local_size_x = 1) in;\nvoid main() { oops; }\n",
                                              &prog, &err);
    CHECK(res == VEIL_ERR_SHADER, "broken shader compiled (%d)", res);
    CHECK(strstr(err.msg, "tests/broken.comp") != NULL, "message does not name the file: %s", err.msg);
    CHECK(strstr(err.msg, "oops") != NULL, "message lacks the driver's log: %s", err.msg);
    veil_gl_destroy(gl);
    return check_finish();
}
