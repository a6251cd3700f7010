/* veil accuracy benchmark — Pareto front, CSV, gnuplot, Markdown (see accuracy_report.h). */
#define _POSIX_C_SOURCE 200809L
#include "accuracy_report.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

static FILE* out_copy;

void acc_out_set_copy(FILE* f) { out_copy = f; }

void acc_out(const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    if (out_copy) {
        va_start(ap, fmt);
        vfprintf(out_copy, fmt, ap);
        va_end(ap);
    }
}

static int metric = ACC_METRIC_PIXEL;

void acc_set_metric(int m) { metric = m; }
double acc_row_error(const acc_row* r) { return metric == ACC_METRIC_BIN ? r->rel_rmse_bin : r->rel_rmse; }
double acc_row_noise(const acc_row* r) { return metric == ACC_METRIC_BIN ? r->ref_noise_bin : r->ref_noise_split; }

const char* acc_metric_name(void)
{
    static char buf[64];
    if (metric == ACC_METRIC_BIN)
        snprintf(buf, sizeof buf, "rel_rmse of %dx%d-pixel means", ACC_BIN, ACC_BIN);
    else
        snprintf(buf, sizeof buf, "rel_rmse per pixel");
    return buf;
}

void acc_mark_pareto(acc_row* rows, size_t n)
{
    for (size_t i = 0; i < n; ++i) {
        acc_row* a = &rows[i];
        double ea = acc_row_error(a);
        a->pareto = isfinite(ea) && isfinite(a->time_ms);
        for (size_t j = 0; j < n && a->pareto; ++j) {
            const acc_row* b = &rows[j];
            double eb = acc_row_error(b);
            if (j == i || strcmp(a->scene, b->scene) != 0 || !isfinite(eb)) continue;
            if (b->time_ms <= a->time_ms && eb <= ea * (1.0 + ACC_PARETO_TOLERANCE) &&
                (b->time_ms < a->time_ms || eb < ea))
                a->pareto = 0;
        }
    }
}

static const char* method_name(veil_opv_method m) { return veil_opv_method_name(veil_opv_method_resolve(m)); }

void acc_print_row_header(void)
{
    acc_out("%-12s %-30s %5s %4s %-16s %-11s %8s %8s %7s %7s %7s | %8s %8s %8s %8s %8s | %8s %8s %8s\n", "scene",
            "setting", "step", "res", "method", "grid", "time_ms", "cpu_ms", "inject", "propag", "render", "rel_rmse",
            "noise_se",
            "noise_sp", "excess", "max_abs", "bin_rmse", "bin_nois", "bin_exc");
}

void acc_print_row(const acc_row* r)
{
    char grid[32];
    snprintf(grid, sizeof grid, "%dx%dx%d", r->dims[0], r->dims[1], r->dims[2]);
    acc_out("%-12s %-30s %5g %4d %-16s %-11s %8.1f %8.1f %7.1f %7.1f %7.1f | %8.5f %8.5f %8.5f %8.5f %8.3g | %8.5f "
            "%8.5f %8.5f\n",
            r->scene, r->setting, (double)r->step_voxels, r->max_resolution, method_name(r->method), grid, r->time_ms,
            r->cpu_ms,
            r->inject_ms, r->propagate_ms, r->render_ms, r->rel_rmse, r->ref_noise, r->ref_noise_split, r->rel_excess,
            r->max_abs, r->rel_rmse_bin, r->ref_noise_bin, r->rel_excess_bin);
}

int acc_write_csv(const char* path, const acc_row* rows, size_t n)
{
    FILE* f = fopen(path, "w");
    if (!f) return 0;
    fprintf(f, "scene,setting,step_voxels,max_resolution,method,grid,runs,time_ms,time_min_ms,cpu_ms,inject_ms,"
               "propagate_ms,render_ms,"
               "rel_rmse,ref_noise,ref_noise_split,rel_rmse_excess,max_abs,psnr_db,frac_off_5pct,"
               "rel_rmse_bin%d,ref_noise_bin%d,rel_rmse_excess_bin%d,pareto\n",
            ACC_BIN, ACC_BIN, ACC_BIN);
    for (size_t i = 0; i < n; ++i) {
        const acc_row* r = &rows[i];
        fprintf(f,
                "%s,%s,%g,%d,%s,%dx%dx%d,%d,%.2f,%.2f,%.2f,%.2f,%.2f,%.2f,%.6g,%.6g,%.6g,%.6g,%.6g,%.4f,%.6g,%.6g,%.6g,"
                "%.6g,%d\n",
                r->scene, r->setting, (double)r->step_voxels, r->max_resolution, method_name(r->method), r->dims[0],
                r->dims[1], r->dims[2], r->runs, r->time_ms, r->time_min_ms, r->cpu_ms, r->inject_ms, r->propagate_ms, r->render_ms, r->rel_rmse,
                r->ref_noise, r->ref_noise_split, r->rel_excess, r->max_abs, r->psnr_db, r->frac_off, r->rel_rmse_bin,
                r->ref_noise_bin, r->rel_excess_bin, r->pareto);
    }
    int ok = !ferror(f);
    if (fclose(f) != 0) ok = 0;
    return ok;
}

static int cmp_time(const void* a, const void* b)
{
    const acc_row* x = *(const acc_row* const*)a;
    const acc_row* y = *(const acc_row* const*)b;
    return x->time_ms < y->time_ms ? -1 : x->time_ms > y->time_ms;
}

/* The rows of one scene (pareto_only: its front), sorted by time, into
 * a newly malloc'd array of pointers. */
static const acc_row** scene_rows(const acc_row* rows, size_t n, const char* scene, int pareto_only, size_t* count)
{
    const acc_row** v = malloc((n ? n : 1) * sizeof *v);
    size_t k = 0;
    for (size_t i = 0; v && i < n; ++i)
        if (strcmp(rows[i].scene, scene) == 0 && (!pareto_only || rows[i].pareto)) v[k++] = &rows[i];
    if (v) qsort(v, k, sizeof *v, cmp_time);
    *count = k;
    return v;
}

void acc_print_pareto_tables(const acc_row* rows, size_t n, const char* const* scenes, int n_scenes)
{
    for (int s = 0; s < n_scenes; ++s) {
        size_t all = 0, k = 0;
        free(scene_rows(rows, n, scenes[s], 0, &all));
        const acc_row** v = scene_rows(rows, n, scenes[s], 1, &k);
        if (!v) continue;
        acc_out("\n### %s: Pareto front (%zu of %zu settings)\n\n", scenes[s], k, all);
        acc_out("| setting | step (voxels) | max_resolution | grid | method | time (ms) | CPU (ms) | rel. RMSE | "
                "ref. noise | excess | rel. RMSE %dx%d | its noise | excess | PSNR (dB) |\n",
                ACC_BIN, ACC_BIN);
        acc_out("|---|---:|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (size_t i = 0; i < k; ++i) {
            const acc_row* r = v[i];
            acc_out("| %s | %g | %d | %d×%d×%d | %s | %.0f | %.0f | %.2f %% | %.2f %% | %.2f %% | %.2f %% | %.2f %% | %.2f %% | "
                    "%.1f |\n",
                    r->setting, (double)r->step_voxels, r->max_resolution, r->dims[0], r->dims[1], r->dims[2],
                    method_name(r->method), r->time_ms, r->cpu_ms, 100.0 * r->rel_rmse, 100.0 * r->ref_noise_split,
                    100.0 * r->rel_excess, 100.0 * r->rel_rmse_bin, 100.0 * r->ref_noise_bin,
                    100.0 * r->rel_excess_bin, r->psnr_db);
        }
        free(v);
    }
}

void acc_print_summary(const acc_row* rows, size_t n, const char* const* scenes, int n_scenes)
{
    acc_out("\n### The default setting (step 0.5 voxel, the scene's max_resolution, %s)\n\n",
            veil_opv_method_name(VEIL_OPV_DEFAULT_METHOD));
    acc_out("| scene | grid | time (ms) | CPU (ms) | rel. RMSE | ref. noise | excess | rel. RMSE %dx%d | its noise | "
            "excess |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
            ACC_BIN, ACC_BIN);
    for (int s = 0; s < n_scenes; ++s)
        for (size_t i = 0; i < n; ++i) {
            const acc_row* r = &rows[i];
            if (strcmp(r->scene, scenes[s]) != 0 || strcmp(r->setting, "default") != 0) continue;
            acc_out("| %s | %d×%d×%d | %.0f | %.0f | %.2f %% | %.2f %% | %.2f %% | %.2f %% | %.2f %% | %.2f %% |\n",
                    r->scene, r->dims[0], r->dims[1], r->dims[2], r->time_ms, r->cpu_ms, 100.0 * r->rel_rmse,
                    100.0 * r->ref_noise_split, 100.0 * r->rel_excess, 100.0 * r->rel_rmse_bin,
                    100.0 * r->ref_noise_bin, 100.0 * r->rel_excess_bin);
        }
    int odd = 0;
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j) {
            const acc_row *a = &rows[i], *b = &rows[j];
            if (strcmp(a->scene, b->scene) != 0 || a->max_resolution != b->max_resolution ||
                a->method != b->method || !(a->step_voxels < b->step_voxels) ||
                !(acc_row_error(a) > 1.5 * acc_row_error(b)))
                continue;
            acc_out("%s# odd: %s %s: %s %.3g %% is over 1.5x that of %s (%.3g %%), whose step is coarser\n",
                    odd++ ? "" : "\n", a->scene, a->setting, acc_metric_name(), 100.0 * acc_row_error(a), b->setting,
                    100.0 * acc_row_error(b));
            break;
        }
}

/* ---- gnuplot --------------------------------------------------------------- */

static int have_gnuplot(void)
{
    int st = system("command -v gnuplot >/dev/null 2>&1");
    return st != -1 && WIFEXITED(st) && WEXITSTATUS(st) == 0;
}

/* Shell-quotes s into buf ('...' with ' as '\''). */
static void shell_quote(const char* s, char* buf, size_t len)
{
    size_t k = 0;
    if (len < 3) return;
    buf[k++] = '\'';
    for (; *s && k + 5 < len; ++s) {
        if (*s == '\'') {
            memcpy(buf + k, "'\\''", 4);
            k += 4;
        } else {
            buf[k++] = *s;
        }
    }
    buf[k++] = '\'';
    buf[k] = '\0';
}

static void data_block(FILE* f, const char* name, const acc_row* const* v, size_t k)
{
    fprintf(f, "$%s << EOD\n", name);
    for (size_t i = 0; i < k; ++i) fprintf(f, "%.4g %.6g \"%s\"\n", v[i]->time_ms, acc_row_error(v[i]), v[i]->setting);
    fprintf(f, "EOD\n");
}

int acc_plot(const char* dir, const char* gp_name, const char* png_name, const char* title, const acc_row* rows,
             size_t n, const char* const* scenes, const double* noise, int n_scenes)
{
    char gp_path[2100];
    snprintf(gp_path, sizeof gp_path, "%s/%s", dir, gp_name);
    FILE* f = fopen(gp_path, "w");
    if (!f) {
        fprintf(stderr, "accuracy: %s: %s (no plot)\n", gp_path, strerror(errno));
        return 0;
    }
    fprintf(f, "# made by build/bench/accuracy: the time-error plane of the fast GPU path against the CPU reference\n"
               "# run in its folder: gnuplot %s\n",
            gp_name);
    fprintf(f, "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
               "  set terminal pngcairo size 1200,800 enhanced font 'sans,11'\n"
               "} else {\n"
               "  set terminal png size 1200,800\n"
               "}\n");
    fprintf(f, "set output '%s'\n", png_name);
    fprintf(f, "set title \"%s\" noenhanced\n", title);
    fprintf(f, "set logscale xy\nset grid xtics ytics mxtics mytics lc rgb '#dddddd'\n");
    fprintf(f, "set xlabel 'fast path: wall time of one uncached frame, ms (inject + propagate + march; median)'\n");
    fprintf(f, "set ylabel 'error against the reference (single scattering): %s' noenhanced\n", acc_metric_name());
    fprintf(f, "set key outside right top noenhanced samplen 2\nset format y '%%g'\n");
    static const char* const colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"};
    for (int s = 0; s < n_scenes; ++s) {
        size_t k = 0, kp = 0;
        const acc_row** all = scene_rows(rows, n, scenes[s], 0, &k);
        const acc_row** front = scene_rows(rows, n, scenes[s], 1, &kp);
        char name[64];
        snprintf(name, sizeof name, "all%d", s);
        data_block(f, name, all, k);
        snprintf(name, sizeof name, "front%d", s);
        data_block(f, name, front, kp);
        fprintf(f, "$default%d << EOD\n", s);
        for (size_t i = 0; i < k; ++i)
            if (strcmp(all[i]->setting, "default") == 0) fprintf(f, "%.4g %.6g\n", all[i]->time_ms, acc_row_error(all[i]));
        fprintf(f, "EOD\n");
        free(all);
        free(front);
    }
    fprintf(f, "plot \\\n");
    fprintf(f, "  NaN with lines lw 2 lc rgb 'black' title 'Pareto front', \\\n"
               "  NaN with points pt 6 ps 2.6 lw 2 lc rgb 'black' title 'default setting', \\\n"
               "  NaN with lines dt 2 lc rgb 'black' title 'reference noise (same scale)'");
    for (int s = 0; s < n_scenes; ++s) {
        const char* c = colours[s % 5];
        fprintf(f, ", \\\n  $all%d using 1:2 with points pt 7 ps 1.2 lc rgb '%s' title '%s', \\\n", s, c, scenes[s]);
        fprintf(f, "  $front%d using 1:2 with lines lw 2 lc rgb '%s' notitle, \\\n", s, c);
        fprintf(f, "  $front%d using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '%s' notitle, \\\n",
                s, c);
        fprintf(f, "  $default%d using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '%s' notitle, \\\n", s, c);
        fprintf(f, "  %.6g with lines dt 2 lw 1 lc rgb '%s' notitle", noise[s] > 0 ? noise[s] : 1e-9, c);
    }
    fprintf(f, "\n");
    int ok = !ferror(f);
    if (fclose(f) != 0 || !ok) {
        fprintf(stderr, "accuracy: writing %s failed (no plot)\n", gp_path);
        return 0;
    }
    if (!have_gnuplot()) {
        fprintf(stderr,
                "accuracy: gnuplot is not installed, so no plot (the CSV is written). Install it with\n"
                "  sudo apt-get install -y gnuplot-nox   (or: sudo bash scripts/install-bench-deps.sh)\n"
                "then draw the plot with: cd %s && gnuplot %s\n",
                dir, gp_name);
        return 0;
    }
    char qd[2100], qg[300], cmd[2500];
    shell_quote(dir, qd, sizeof qd);
    shell_quote(gp_name, qg, sizeof qg);
    snprintf(cmd, sizeof cmd, "cd %s && gnuplot %s", qd, qg);
    int st = system(cmd);
    if (st == -1 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "accuracy: `%s` failed (no plot)\n", cmd);
        return 0;
    }
    return 1;
}
