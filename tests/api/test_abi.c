/* The ABI, as a program linked against libveil.so sees it (include/ only,
 * no internal header, no static library):
 *  - the version: veil.h's VEIL_VERSION_MAJOR/MINOR/PATCH equal what the
 *    loaded library answers (veil_version_numbers, veil_version) and the
 *    CMake project's version (VEIL_TEST_CMAKE_VERSION); the answers come
 *    from libveil.so itself (dladdr of veil_version()'s string), not from
 *    a copy linked in;
 *  - growing descriptions, GPU-free: veil_context_create refuses a
 *    veil_context_desc whose size is larger than the library's or the
 *    size of no layout, with VEIL_ERR_INVALID, a message naming both
 *    sizes, and *out NULL, before any GL context is made;
 *  - with "render SCENE": veil 0.2's render desc layout with a junk tail
 *    renders as the new one (the progress callback is not read from it);
 *    a render desc of size 0 (an old zeroed
 *    description), one from VEIL_RENDER_DESC_INIT and one followed by
 *    junk bytes agree bit for bit; too large or unknown sizes are refused the same
 *    way; a context from VEIL_CONTEXT_DESC_INIT renders. Exit 77 (skipped)
 *    when no GL context can be made, except under CI=true. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <veil.h>

static int passed, failed;
#define CHECK(cond, ...)                                                                \
    do {                                                                                \
        if (cond) {                                                                     \
            ++passed;                                                                   \
        } else {                                                                        \
            ++failed;                                                                   \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);    \
            fprintf(stderr, __VA_ARGS__);                                               \
            fputc('\n', stderr);                                                        \
        }                                                                               \
    } while (0)

static void versions(void)
{
    int major = -1, minor = -1, patch = -1;
    veil_version_numbers(&major, &minor, &patch);
    CHECK(major == VEIL_VERSION_MAJOR && minor == VEIL_VERSION_MINOR && patch == VEIL_VERSION_PATCH,
          "library %d.%d.%d, header %d.%d.%d", major, minor, patch, VEIL_VERSION_MAJOR, VEIL_VERSION_MINOR,
          VEIL_VERSION_PATCH);
    veil_version_numbers(NULL, NULL, NULL); /* each output may be NULL */
    char header[64];
    snprintf(header, sizeof header, "%d.%d.%d", VEIL_VERSION_MAJOR, VEIL_VERSION_MINOR, VEIL_VERSION_PATCH);
    CHECK(veil_version() && strcmp(veil_version(), header) == 0, "veil_version() %s, header %s", veil_version(),
          header);
    CHECK(strcmp(VEIL_TEST_CMAKE_VERSION, header) == 0, "CMake's project version %s, header %s",
          VEIL_TEST_CMAKE_VERSION, header);

    /* the string veil_version() returns lies in the library that answered */
    Dl_info where = {0};
    CHECK(dladdr(veil_version(), &where) && where.dli_fname && strstr(where.dli_fname, "libveil.so"),
          "veil_version() answered from %s, not libveil.so", where.dli_fname ? where.dli_fname : "(unknown)");
}

/* A description inside a larger buffer, so that a library reading past
 * `size` would read bytes the test set (and a sanitizer would not see). */
typedef struct {
    veil_context_desc desc;
    unsigned char beyond[64];
} padded_context_desc;

static void context_desc_sizes(void)
{
    const size_t own = sizeof(veil_context_desc);
    const size_t bad[] = {own + sizeof(int), own + 64, 1, sizeof(size_t), own - 1};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        padded_context_desc p;
        memset(&p, 0xA5, sizeof p);
        p.desc.size = bad[i];
        veil_error err = {{0}};
        veil_context* ctx = (veil_context*)&p; /* must be reset to NULL */
        veil_result r = veil_context_create(&p.desc, &ctx, &err);
        char size_text[32];
        snprintf(size_text, sizeof size_text, "size is %zu bytes", bad[i]);
        CHECK(r == VEIL_ERR_INVALID && ctx == NULL, "context desc size %zu: %s", bad[i], veil_result_name(r));
        CHECK(strstr(err.msg, "veil_context_desc") && strstr(err.msg, size_text), "size %zu: message: %s", bad[i],
              err.msg);
        veil_context_destroy(r == VEIL_OK ? ctx : NULL);
    }
}

static int same_pixels(const veil_image* a, const veil_image* b)
{
    int wa, ha, wb, hb;
    veil_image_size(a, &wa, &ha);
    veil_image_size(b, &wb, &hb);
    return a && b && wa == wb && ha == hb &&
           memcmp(veil_image_rgba(a), veil_image_rgba(b), (size_t)wa * ha * 4 * sizeof(float)) == 0;
}

typedef struct {
    veil_render_desc desc;
    unsigned char beyond[64];
} padded_render_desc;

static int render_desc_sizes(const char* scene_path)
{
    veil_error err = {{0}};
    veil_context* ctx = NULL;
    veil_context_desc cdesc = VEIL_CONTEXT_DESC_INIT;
    CHECK(cdesc.size == sizeof cdesc && cdesc.force_software == 0 && cdesc.debug == 0, "VEIL_CONTEXT_DESC_INIT");
    veil_result r = veil_context_create(&cdesc, &ctx, &err);
    if (r == VEIL_ERR_GPU) {
        const char* ci = getenv("CI");
        if (ci && strcmp(ci, "true") == 0) {
            fprintf(stderr, "FAIL: no GL 4.5 context under CI: %s\n", err.msg);
            return 1;
        }
        fprintf(stderr, "SKIPPED: no GL 4.5 context: %s\n", err.msg);
        return 77;
    }
    CHECK(r == VEIL_OK && ctx, "context from VEIL_CONTEXT_DESC_INIT: %s", err.msg);
    veil_scene* scene = NULL;
    if (r == VEIL_OK) r = veil_scene_open(scene_path, &scene, &err);
    CHECK(r == VEIL_OK, "open %s: %s", scene_path, err.msg);
    if (r != VEIL_OK) {
        veil_context_destroy(ctx);
        return 1;
    }

    /* The same request three ways: an old zeroed description (size 0), the
     * initializer, and the initializer inside a buffer whose tail is junk. */
    veil_render_desc old = {.width = 32, .height = 24, .seed = 11};
    veil_render_desc init = VEIL_RENDER_DESC_INIT;
    CHECK(init.size == sizeof init && init.width == 0 && init.frames == 0, "VEIL_RENDER_DESC_INIT");
    init.width = 32, init.height = 24, init.seed = 11;
    padded_render_desc padded;
    memset(&padded, 0x5A, sizeof padded);
    padded.desc = init;
    veil_image *a = NULL, *b = NULL, *c = NULL;
    CHECK(veil_render(ctx, scene, &old, &a, &err) == VEIL_OK, "size 0: %s", err.msg);
    CHECK(veil_render(ctx, scene, &init, &b, &err) == VEIL_OK, "size %zu: %s", init.size, err.msg);
    CHECK(veil_render(ctx, scene, &padded.desc, &c, &err) == VEIL_OK, "padded: %s", err.msg);
    int w = 0, h = 0;
    veil_image_size(a, &w, &h);
    CHECK(w == 32 && h == 24, "size 0 desc read: %dx%d", w, h);
    CHECK(same_pixels(a, b) && same_pixels(a, c), "size 0, VEIL_RENDER_DESC_INIT and padded differ");

    /* A program built against veil 0.2's header passes 0.2's layout (no progress callback) with its
     * own size: the library reads those fields and no further (a junk tail read as the callback
     * would be called and crash), the same image. */
    typedef struct {
        size_t size;
        int width, height;
        float step_voxels;
        uint32_t seed;
        long frame, frames;
    } render_desc_0_2;
    struct {
        render_desc_0_2 desc;
        unsigned char tail[64];
    } v02;
    memset(&v02, 0x5A, sizeof v02);
    v02.desc = (render_desc_0_2){sizeof(render_desc_0_2), 32, 24, 0.0f, 11u, 0L, 0L};
    veil_image* d = NULL;
    CHECK(veil_render(ctx, scene, (const veil_render_desc*)(const void*)&v02.desc, &d, &err) == VEIL_OK,
          "veil 0.2's layout (size %zu): %s", sizeof(render_desc_0_2), err.msg);
    CHECK(d && same_pixels(a, d), "veil 0.2's layout renders another image");
    veil_image_destroy(d);

    const size_t own = sizeof(veil_render_desc);
    const size_t bad[] = {own + sizeof(long), own + 64, 3, sizeof(size_t), own - sizeof(long)};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        memset(&padded, 0x5A, sizeof padded);
        padded.desc = init;
        padded.desc.size = bad[i];
        veil_error e = {{0}};
        veil_image* img = (veil_image*)&padded; /* must be reset to NULL */
        r = veil_render(ctx, scene, &padded.desc, &img, &e);
        char size_text[32];
        snprintf(size_text, sizeof size_text, "size is %zu bytes", bad[i]);
        CHECK(r == VEIL_ERR_INVALID && img == NULL, "render desc size %zu: %s", bad[i], veil_result_name(r));
        CHECK(strstr(e.msg, "veil_render_desc") && strstr(e.msg, size_text), "size %zu: message: %s", bad[i], e.msg);
        veil_image_destroy(r == VEIL_OK ? img : NULL);
    }
    veil_image_destroy(a);
    veil_image_destroy(b);
    veil_image_destroy(c);
    veil_scene_close(scene);
    veil_context_destroy(ctx);
    return 0;
}

int main(int argc, char** argv)
{
    int code = 0;
    if (argc == 3 && strcmp(argv[1], "render") == 0) {
        code = render_desc_sizes(argv[2]);
        if (code == 77) return 77;
    } else if (argc == 1) {
        versions();
        context_desc_sizes();
    } else {
        fprintf(stderr, "usage: %s [render SCENE]\n", argv[0]);
        return 2;
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed || code ? 1 : 0;
}
