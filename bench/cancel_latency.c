/* How soon a cancel takes effect (issue 41: "cancel effective within 1 s at
 * any point"), through the public API as a caller (Python's Ctrl-C, Blender's
 * Esc) meets it:
 *
 *   cancel_latency [--width W --height H] [--cancels K] SCENE.json...
 *
 * For each scene, on a fresh context each time (so that every stage runs):
 *  1. the scene read (veil_scene_create) and a whole render with a progress
 *     callback that only notes the time of each call: the longest gap
 *     between two calls (and from the call's start to the first, from the
 *     last to its return), and in which stage it ends. A cancel asked for
 *     at any moment waits for the next call, so this gap bounds how late a
 *     Ctrl-C is seen;
 *  2. K renders cancelled at calls spread evenly over a render's calls: the
 *     time from the cancelling call's return to veil_render's return (the
 *     work in flight).
 * The worst latency at any point is at most the longest gap plus the
 * longest return. Prints one line per scene and the worst over all;
 * VEIL_BENCH_VERBOSE=1 prints every call (stage, share, time since the
 * last) on stderr. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "include/veil.h"

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

typedef struct timing {
    double last, gap;        /* the time of the last call; the longest gap so far */
    char gap_stage[32];      /* the stage of the call that ended it ("return": the call's own return) */
    int calls, cancel_at;    /* cancel at this call (0: never) */
    double cancelled_at;     /* when the cancelling call returned */
} timing;

static int on_call(void* user, const char* stage, double done)
{
    (void)done;
    timing* t = user;
    const double now = now_ms();
    if (now - t->last > t->gap) {
        t->gap = now - t->last;
        snprintf(t->gap_stage, sizeof t->gap_stage, "%s", stage);
    }
    if (getenv("VEIL_BENCH_VERBOSE")) fprintf(stderr, "  %-10s %.3f after %.0f ms\n", stage, done, now - t->last);
    t->last = now;
    if (++t->calls == t->cancel_at) {
        t->cancelled_at = now_ms();
        return 1;
    }
    return 0;
}

static void end_gap(timing* t)
{
    const double now = now_ms();
    if (now - t->last > t->gap) {
        t->gap = now - t->last;
        snprintf(t->gap_stage, sizeof t->gap_stage, "return");
    }
}

int main(int argc, char** argv)
{
    veil_render_desc d = VEIL_RENDER_DESC_INIT;
    int cancels = 8, first = 1;
    for (; first < argc && argv[first][0] == '-'; first += 2) {
        if (first + 1 >= argc) break;
        if (!strcmp(argv[first], "--width")) d.width = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--height")) d.height = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--cancels")) cancels = atoi(argv[first + 1]);
        else break;
    }
    if (first >= argc) {
        fprintf(stderr, "usage: cancel_latency [--width W --height H] [--cancels K] SCENE.json...\n");
        return 2;
    }
    double worst_gap = 0.0, worst_return = 0.0;
    printf("%-28s %8s %9s %-26s %12s %12s\n", "scene", "calls", "render ms", "longest gap (ms, ends in)",
           "read gap ms", "return ms");
    for (int a = first; a < argc; ++a) {
        veil_error err = {{0}};
        veil_scene* s = NULL;
        timing rt = {.last = now_ms()};
        veil_scene_desc sd = VEIL_SCENE_DESC_INIT;
        sd.path = argv[a], sd.progress = on_call, sd.progress_user = &rt;
        if (veil_scene_create(&sd, &s, &err) != VEIL_OK) {
            fprintf(stderr, "%s: %s\n", argv[a], err.msg);
            return 1;
        }
        end_gap(&rt);
        veil_context* ctx = NULL;
        if (veil_context_create(NULL, &ctx, &err) != VEIL_OK) {
            fprintf(stderr, "no context: %s\n", err.msg);
            return 1;
        }
        timing whole = {.last = now_ms()};
        const double t0 = whole.last;
        veil_image* img = NULL;
        d.progress = on_call, d.progress_user = &whole;
        veil_result r = veil_render(ctx, s, &d, &img, &err);
        end_gap(&whole);
        const double render_ms = now_ms() - t0;
        veil_image_destroy(img);
        veil_context_destroy(ctx);
        if (r != VEIL_OK) {
            fprintf(stderr, "%s: %s\n", argv[a], err.msg);
            return 1;
        }
        double ret = 0.0;
        for (int k = 0; k < cancels && whole.calls > 1; ++k) {
            timing c = {.last = now_ms(), .cancel_at = 1 + (int)((double)k * (whole.calls - 1) / cancels)};
            if (veil_context_create(NULL, &ctx, &err) != VEIL_OK) return 1;
            d.progress_user = &c;
            r = veil_render(ctx, s, &d, &img, &err);
            const double back = now_ms() - c.cancelled_at;
            veil_image_destroy(img);
            img = NULL;
            veil_context_destroy(ctx);
            if (r != VEIL_ERR_CANCELLED) {
                fprintf(stderr, "%s: cancel at call %d: %s (%s)\n", argv[a], c.cancel_at, veil_result_name(r), err.msg);
                return 1;
            }
            if (back > ret) ret = back;
        }
        const char* name = strrchr(argv[a], '/');
        char gap[64];
        snprintf(gap, sizeof gap, "%.0f (%s)", whole.gap, whole.gap_stage);
        printf("%-28s %8d %9.0f %-26s %12.0f %12.0f\n", name ? name + 1 : argv[a], whole.calls, render_ms, gap,
               rt.gap, ret);
        worst_gap = whole.gap > worst_gap ? whole.gap : worst_gap;
        worst_gap = rt.gap > worst_gap ? rt.gap : worst_gap;
        worst_return = ret > worst_return ? ret : worst_return;
        veil_scene_close(s);
    }
    printf("worst: a gap of %.0f ms, a return of %.0f ms: a cancel takes effect within %.0f ms\n", worst_gap,
           worst_return, worst_gap + worst_return);
    return 0;
}
