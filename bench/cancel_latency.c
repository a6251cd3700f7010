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
 *  2. K renders cancelled at calls spread evenly over a render's calls
 *     (--cancels all: at every call): the time from the cancelling call's
 *     return to veil_render's return (the work in flight).
 * A cancel asked for at a moment in the gap before call k takes effect
 * after at most gap_k + return_k; with every call measured the worst of
 * those is the worst latency at any point ("worst"); with a sample, the
 * longest gap plus the longest return bounds it. Prints one line per scene
 * and the worst over all;
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

enum { MAX_CALLS = 4096 };
typedef struct timing {
    double last, gap;        /* the time of the last call; the longest gap so far */
    char gap_stage[32];      /* the stage of the call that ended it ("return": the call's own return) */
    int calls, cancel_at;    /* cancel at this call (0: never) */
    double cancelled_at;     /* when the cancelling call returned */
    double gaps[MAX_CALLS];  /* the gap before each call */
    char stages[MAX_CALLS][12];
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
    if (t->calls < MAX_CALLS) {
        t->gaps[t->calls] = now - t->last;
        snprintf(t->stages[t->calls], sizeof t->stages[0], "%s", stage);
    }
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
        else if (!strcmp(argv[first], "--cancels")) cancels = !strcmp(argv[first + 1], "all") ? -1 : atoi(argv[first + 1]);
        else break;
    }
    if (first >= argc) {
        fprintf(stderr, "usage: cancel_latency [--width W --height H] [--cancels K] SCENE.json...\n");
        return 2;
    }
    double worst_gap = 0.0, worst_return = 0.0, worst_any = 0.0;
    printf("%-24s %6s %9s %-26s %8s %9s %-22s\n", "scene", "calls", "render ms", "longest gap (ms, ends in)",
           "read gap", "return ms", "worst ms (call k)");
    for (int a = first; a < argc; ++a) {
        veil_error err = {{0}};
        veil_scene* s = NULL;
        static timing rt, whole;
        memset(&rt, 0, sizeof rt);
        rt.last = now_ms();
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
        memset(&whole, 0, sizeof whole);
        whole.last = now_ms();
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
        double ret = 0.0, worst = -1.0;
        int worst_at = 0;
        const int runs = cancels < 0 ? whole.calls : cancels;
        static timing c;
        for (int k = 0; k < runs && whole.calls > 1; ++k) {
            memset(&c, 0, sizeof c);
            c.last = now_ms();
            c.cancel_at = cancels < 0 ? k + 1 : 1 + (int)((double)k * (whole.calls - 1) / cancels);
            if (veil_context_create(NULL, &ctx, &err) != VEIL_OK) return 1;
            d.progress_user = &c;
            r = veil_render(ctx, s, &d, &img, &err);
            const double back = now_ms() - c.cancelled_at;
            veil_image_destroy(img);
            img = NULL;
            veil_context_destroy(ctx);
            /* VEIL_OK: the cancel came at a report after which no work could be cut short (the last stage's
             * end: the render returns its image); its return still counts */
            if (r != VEIL_ERR_CANCELLED && r != VEIL_OK) {
                fprintf(stderr, "%s: cancel at call %d: %s (%s)\n", argv[a], c.cancel_at, veil_result_name(r), err.msg);
                return 1;
            }
            if (back > ret) ret = back;
            /* a cancel asked for in the gap before this call: that gap (the whole render's), then this return */
            const int i = c.cancel_at - 1;
            if (cancels < 0 && i < MAX_CALLS && whole.gaps[i] + back > worst) worst = whole.gaps[i] + back, worst_at = i;
        }
        const char* name = strrchr(argv[a], '/');
        char gap[64], at[64] = "-";
        snprintf(gap, sizeof gap, "%.0f (%s)", whole.gap, whole.gap_stage);
        if (worst >= 0.0) {
            snprintf(at, sizeof at, "%.0f (%d, %s)", worst, worst_at + 1, whole.stages[worst_at]);
            worst_any = worst > worst_any ? worst : worst_any;
        }
        printf("%-24s %6d %9.0f %-26s %8.0f %9.0f %-22s\n", name ? name + 1 : argv[a], whole.calls, render_ms, gap,
               rt.gap, ret, at);
        worst_gap = whole.gap > worst_gap ? whole.gap : worst_gap;
        worst_gap = rt.gap > worst_gap ? rt.gap : worst_gap;
        worst_return = ret > worst_return ? ret : worst_return;
        veil_scene_close(s);
    }
    printf("worst: a gap of %.0f ms, a return of %.0f ms: a cancel takes effect within %.0f ms", worst_gap,
           worst_return, worst_gap + worst_return);
    if (cancels < 0) printf(" (measured at every call: %.0f ms)", worst_any > worst_gap ? worst_any : worst_gap);
    printf("\n");
    return 0;
}
