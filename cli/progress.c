#define _POSIX_C_SOURCE 200809L
#include "progress.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/clock.h"
#include "core/progress.h"

static int g_mode; /* veil_cli_progress_mode */

void veil_cli_progress_mode(int mode) { g_mode = mode; }

static struct {
    int on;
    char label[96];
    char what[96];
    double start_ms, drawn_ms;
} g_line;

static void draw(void* user, const char* what, double done, double total)
{
    (void)user;
    const double now = veil_now_ms();
    const int changed = strncmp(what, g_line.what, sizeof g_line.what - 1) != 0;
    if (!changed && now - g_line.drawn_ms < 200.0 && done < total) return;
    snprintf(g_line.what, sizeof g_line.what, "%s", what);
    g_line.drawn_ms = now;
    char pct[16] = "";
    if (total > 1.0 && done >= 0.0 && done <= total) snprintf(pct, sizeof pct, " %.0f%%", 100.0 * done / total);
    /* \r and erase-to-end: one line, redrawn in place */
    fprintf(stderr, "\r\033[Kveil: %s%s%.60s%s, %.1f s", g_line.label, g_line.label[0] ? ": " : "", what, pct,
            (now - g_line.start_ms) * 1e-3);
    fflush(stderr);
}

void veil_cli_progress_begin(const char* label)
{
    const char* term = getenv("TERM");
    if (g_mode < 0) return;
    if (g_mode == 0 && (!isatty(STDERR_FILENO) || (term && strcmp(term, "dumb") == 0))) return;
    snprintf(g_line.label, sizeof g_line.label, "%s", label ? label : "");
    g_line.what[0] = '\0';
    g_line.start_ms = veil_now_ms();
    g_line.drawn_ms = 0.0;
    g_line.on = 1;
    veil_progress_sink(draw, NULL, NULL);
}

void veil_cli_progress_end(void)
{
    if (!g_line.on) return;
    veil_progress_sink(NULL, NULL, NULL);
    g_line.on = 0;
    fputs("\r\033[K", stderr);
    fflush(stderr);
}
