/* Renders a scene file to an EXR through veil's public API.
 *
 *   render_scene SCENE.json OUT.exr [WIDTH HEIGHT]
 *
 * Prints each stage's report and the path written. Exit 0 on success, 1 on
 * an error (its message on stderr) or when the loaded libveil.so is not
 * the version <veil.h> describes, 2 on bad arguments, 3 when no GL 4.5
 * context can be made (a test can skip). */
#include <stdio.h>
#include <stdlib.h>

#include <veil.h>

static int fail(veil_result r, const veil_error* err)
{
    fprintf(stderr, "render_scene: %s: %s\n", veil_result_name(r), err->msg);
    return 1;
}

int main(int argc, char** argv)
{
    if (argc != 3 && argc != 5) {
        fprintf(stderr, "usage: %s SCENE.json OUT.exr [WIDTH HEIGHT]\n", argv[0]);
        return 2;
    }
    int major, minor, patch;
    veil_version_numbers(&major, &minor, &patch);
    if (major != VEIL_VERSION_MAJOR || minor != VEIL_VERSION_MINOR) {
        fprintf(stderr, "render_scene: built against veil %d.%d, running with %s\n", VEIL_VERSION_MAJOR,
                VEIL_VERSION_MINOR, veil_version());
        return 1;
    }
    /* the size set, every other field zero: the scene's size, default step, seed 0 */
    veil_render_desc desc = VEIL_RENDER_DESC_INIT;
    if (argc == 5) {
        desc.width = atoi(argv[3]);
        desc.height = atoi(argv[4]);
    }
    veil_error err = {{0}};
    veil_context* ctx = NULL;
    veil_result r = veil_context_create(NULL, &ctx, &err);
    if (r != VEIL_OK) {
        fprintf(stderr, "render_scene: %s: %s\n", veil_result_name(r), err.msg);
        return r == VEIL_ERR_GPU ? 3 : 1;
    }
    veil_scene* scene = NULL;
    veil_image* img = NULL;
    r = veil_scene_open(argv[1], &scene, &err);
    if (r == VEIL_OK) r = veil_render(ctx, scene, &desc, &img, &err);
    if (r == VEIL_OK) r = veil_image_write_exr(img, argv[2], 0, &err);
    if (r == VEIL_OK) {
        for (int i = 0; i < veil_image_stage_count(img); ++i) {
            const char *name, *status, *why;
            double ms;
            if (veil_image_stage(img, i, &name, &status, &ms, &why) == VEIL_OK)
                printf("%-9s %-7s %8.2f ms  %s\n", name, status, ms, why);
        }
        int w, h;
        veil_image_size(img, &w, &h);
        printf("wrote %s (%dx%d, veil %s)\n", argv[2], w, h, veil_version());
    }
    int code = r == VEIL_OK ? 0 : fail(r, &err);
    veil_image_destroy(img);
    veil_scene_close(scene);
    veil_context_destroy(ctx);
    return code;
}
