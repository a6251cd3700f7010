/* veil accuracy benchmark — its rows and what is made of them: the Pareto
 * front, the CSV, the gnuplot script (and PNG), the Markdown tables. */
#ifndef VEIL_BENCH_ACCURACY_REPORT_H
#define VEIL_BENCH_ACCURACY_REPORT_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include "propagate/opv.h"

/* Block size (pixels a side) of the binned comparison. */
#define ACC_BIN 4

typedef struct acc_row {
    const char* scene;
    char setting[64];   /* "default", or what differs from it: "step=0.25+res=64" */
    float step_voxels;
    int max_resolution;
    veil_opv_method method;
    int dims[3];        /* the fast path's EV */
    int runs;
    double time_ms;     /* median wall time of a whole uncached frame */
    double time_min_ms; /* the fastest run's wall time */
    double cpu_ms;      /* median CPU time of the process (all threads: llvmpipe's too) */
    double inject_ms, propagate_ms, render_ms; /* stages of the median run */
    double rel_rmse;    /* veil_compare_images(fast, reference) */
    double ref_noise;   /* rms over values of stderr / max(|ref|, floor) */
    double ref_noise_split; /* the same from the halves: |h0 - h1| / 2 for stderr */
    double rel_excess;  /* sqrt(max(0, rel_rmse^2 - ref_noise_split^2)) */
    double max_abs, psnr_db, frac_off;
    /* the same on images of ACC_BIN x ACC_BIN pixel means */
    double rel_rmse_bin, ref_noise_bin, rel_excess_bin;
    int pareto;
} acc_row;

/* The error the Pareto front, the plot and the tables rank by:
 * rel_rmse (per pixel) or rel_rmse_bin (ACC_BIN x ACC_BIN means). */
enum { ACC_METRIC_PIXEL, ACC_METRIC_BIN };
void acc_set_metric(int metric);
double acc_row_error(const acc_row* r);
double acc_row_noise(const acc_row* r); /* the reference noise on the same scale */
const char* acc_metric_name(void);

/* Marks rows[i].pareto for the rows of each scene that no other row of the
 * same scene dominates: row b dominates row a when b is no slower and its
 * error is at most a's times (1 + ACC_PARETO_TOLERANCE), and b is faster
 * or its error is smaller. Errors within the tolerance count as equal: it
 * is about the precision of the noise estimate, and without it settings
 * that differ in the fifth digit of a noise-dominated error make the front. */
#define ACC_PARETO_TOLERANCE 0.02
void acc_mark_pareto(acc_row* rows, size_t n);

/* Output that goes to stdout and, when set, to a copy (the .txt). */
void acc_out_set_copy(FILE* f);
void acc_out(const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* One progress row (as measured) and its header. */
void acc_print_row_header(void);
void acc_print_row(const acc_row* r);

/* Per scene, the Markdown table of its Pareto points (by time). */
void acc_print_pareto_tables(const acc_row* rows, size_t n, const char* const* scenes, int n_scenes);

/* Per scene, the default setting's row (a Markdown table), then every row
 * whose error is over 1.5x that of a row that differs only by a coarser
 * step ("odd": a finer step should not be worse). */
void acc_print_summary(const acc_row* rows, size_t n, const char* const* scenes, int n_scenes);

/* The CSV (one row each); 0 on failure (errno set). */
int acc_write_csv(const char* path, const acc_row* rows, size_t n);

/* Writes the gnuplot script dir/gp_name that draws dir/png_name from the
 * rows (data inline; the script names the PNG relative to its folder, so
 * it runs as `cd dir && gnuplot gp_name`) and runs gnuplot there when
 * there is one; returns 1 when the PNG was made, 0 otherwise (with the
 * reason and the fix on stderr). noise[s]: the reference noise of scene s
 * on the plotted scale, drawn as a dashed line. */
int acc_plot(const char* dir, const char* gp_name, const char* png_name, const char* title, const acc_row* rows,
             size_t n, const char* const* scenes, const double* noise, int n_scenes);

#endif
