/* veil CLI — a status line on a terminal for the work under way
 * (core/progress.h): "veil: frame 2/36: RBF splat 45%, 12.3 s",
 * redrawn in place at most five times a second and erased when the work
 * ends. Nothing is drawn when stderr is not a terminal (logs, pipes, CI). */
#ifndef VEIL_CLI_PROGRESS_H
#define VEIL_CLI_PROGRESS_H

/* 0: on a terminal only (the default), 1: always (--progress: also into a
 * pipe or a log, each redraw then a line of its own starting with \r),
 * -1: never (--quiet). */
void veil_cli_progress_mode(int mode);

/* label: what the line is about ("frame 2/36"; NULL: nothing), copied. */
void veil_cli_progress_begin(const char* label);
void veil_cli_progress_end(void);

#endif
