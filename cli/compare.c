/* veil compare A.exr REF.exr [--heatmap OUT.png] [--floor F] [--bin B] [--json]
 *
 * Compares image A against the reference REF (reference/compare.h has the
 * metrics) and prints them, one a line (`rel_rmse 0.0123 (floor ...)`), or
 * with --json as one JSON object:
 *   {"image", "reference": paths, "width", "height", "floor", "rel_rmse",
 *    "rmse", "max_abs", "off_5pct", "psnr_db", "alpha_max_abs",
 *    "heatmap": path or null}
 * plus "bin", "mean_bias" and, when REF holds the standard errors that
 * `veil reference` writes (stderr.R, .G, .B), "noise", "rel_rmse_excess"
 * and "mean_bias_se" (null without them).
 * --bin B compares the means of B x B pixel blocks (a partial block at an
 * edge dropped): the reference's noise falls B times, systematic errors
 * stay. mean_bias = mean(A RGB) / mean(REF RGB) - 1. noise is the rms of
 * the reference's standard error relative to it (same floor, binned
 * alike; a pixel whose stderr.bound is 1 adds no noise: its error is a
 * bound, not an estimate); rel_rmse_excess = sqrt(max(0, rel_rmse^2 - noise^2)) is the
 * image's own error with the reference's noise taken out (they add in
 * quadrature, being independent). mean_bias_se is mean_bias's standard
 * error from the reference's noise (veil_compare_bias_se): a bias within
 * two or three of it is not one the reference can tell from 0.
 * Numbers are JSON numbers; "psnr_db" is null when the images' RGB are
 * identical (MSE 0, PSNR infinite; the text form prints "inf"). No NaN is
 * ever printed: every other number is finite for finite inputs.
 *
 * --heatmap OUT.png writes the per-pixel relative error (largest RGB
 * channel, same floor) as an 8-bit RGB PNG through the colour map of
 * veil_compare_heatmap_colour: log scale, black 1e-4 (and below, 0
 * included), blue 1e-3, magenta 1e-2, yellow 1e-1, white 1 (and above).
 *
 * Exit codes: 0 compared, 1 bad input (a file missing, unreadable or not an
 * EXR, sizes that differ, a non-finite pixel, the heatmap not writable; no
 * heatmap is left behind), 2 usage.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/image.h"
#include "reference/compare.h"
#include "cli_util.h"
#include "core/text.h"
#include "commands.h"

typedef struct compare_args {
    const char *image, *reference, *heatmap;
    double floor; /* 0: the default */
    int json;
    int bin;      /* 1: per pixel */
} compare_args;

/* A number (strtod syntax), positive and finite. */
static int parse_positive(const char* s, double* out)
{
    char* end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v) || !(v > 0.0)) return 0;
    *out = v;
    return 1;
}

/* -1 when the arguments are good, else the exit code. */
static int parse_args(int argc, char** argv, compare_args* a)
{
    memset(a, 0, sizeof *a);
    a->bin = 1;
    for (int i = 2; i < argc; ++i) {
        const char* s = argv[i];
        const char* v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(s, "--json")) {
            a->json = 1;
        } else if (!strcmp(s, "--bin")) {
            char* end;
            long b = v ? strtol(v, &end, 10) : 0;
            if (!v) return veil_cli_usage_error("%s needs a value", s);
            if (*v == 0 || *end || b < 1 || b > 4096)
                return veil_cli_usage_error("--bin: expected an integer in 1..4096 (pixels a side), got '%s'", v);
            a->bin = (int)b;
            ++i;
        } else if (!strcmp(s, "--heatmap") || !strcmp(s, "--floor")) {
            if (!v) return veil_cli_usage_error("%s needs a value", s);
            ++i;
            if (!strcmp(s, "--heatmap")) {
                if (!*v) return veil_cli_usage_error("%s", "--heatmap: expected a file name, got ''");
                a->heatmap = v;
            } else if (!parse_positive(v, &a->floor)) {
                return veil_cli_usage_error(
                    "--floor: expected a positive finite number (absolute, in the images' units), got '%s'", v);
            } else if (a->floor < VEIL_COMPARE_TINY_FLOOR) { /* it would be raised to it without a word */
                return veil_cli_usage_error("--floor: expected a number >= 1e-12 (the smallest floor that keeps "
                                            "every ratio finite), got '%s'", v);
            }
        } else if (s[0] == '-' && s[1]) {
            return veil_cli_usage_error("unknown option '%s'", s);
        } else if (!a->image) {
            a->image = s;
        } else if (!a->reference) {
            a->reference = s;
        } else {
            return veil_cli_usage_error("unexpected argument '%s'", s);
        }
    }
    if (!a->image) return veil_cli_usage_error("%s", "compare: missing A.exr and REF.exr");
    if (!a->reference) return veil_cli_usage_error("%s", "compare: missing REF.exr");
    return -1;
}

/* A JSON string: quotes, backslashes and control characters escaped; other
 * bytes (UTF-8 file names) as they are. */
static void print_json_string(const char* s)
{
    char text[3 * 4096 + 1]; /* bytes that are not UTF-8 become U+FFFD (core/text.h): JSON holds text only */
    veil_text_utf8(s, text, sizeof text);
    putchar('"');
    for (const unsigned char* p = (const unsigned char*)text; *p; ++p) {
        if (*p == '"' || *p == '\\') printf("\\%c", *p);
        else if (*p < 0x20) printf("\\u%04x", *p);
        else putchar(*p);
    }
    putchar('"');
}

/* A JSON number; null for a non-finite value (only PSNR can be one). */
static void print_json_number(const char* key, double v, const char* after)
{
    printf("  \"%s\": ", key);
    if (isfinite(v)) printf("%.17g", v);
    else fputs("null", stdout);
    fputs(after, stdout);
}

typedef struct extra_stats {
    double bias, noise, excess, bias_se; /* noise, excess, bias_se: NAN without standard errors */
    size_t bounded;             /* reference pixels whose standard error is a bound (not counted as noise) */
} extra_stats;

static void print_json(const compare_args* a, const veil_compare_stats* st, const extra_stats* x)
{
    fputs("{\n  \"image\": ", stdout);
    print_json_string(a->image);
    fputs(",\n  \"reference\": ", stdout);
    print_json_string(a->reference);
    printf(",\n  \"width\": %d,\n  \"height\": %d,\n", st->width, st->height);
    print_json_number("floor", st->floor, ",\n");
    print_json_number("rel_rmse", st->rel_rmse, ",\n");
    print_json_number("rmse", st->rmse, ",\n");
    print_json_number("max_abs", st->max_abs, ",\n");
    print_json_number("off_5pct", st->frac_off, ",\n");
    print_json_number("psnr_db", st->psnr_db, ",\n");
    print_json_number("alpha_max_abs", st->alpha_max_abs, ",\n");
    printf("  \"bin\": %d,\n", a->bin);
    print_json_number("mean_bias", x->bias, ",\n");
    print_json_number("noise", x->noise, ",\n");
    print_json_number("rel_rmse_excess", x->excess, ",\n");
    print_json_number("mean_bias_se", x->bias_se, ",\n");
    fputs("  \"heatmap\": ", stdout);
    if (a->heatmap) print_json_string(a->heatmap);
    else fputs("null", stdout);
    fputs("\n}\n", stdout);
}

/* A power of ten as "1e-4" ("1" for 10^0): the heatmap's scale is whole decades. */
static void decade(double v, char out[16])
{
    long e = lround(log10(v));
    if (e == 0) snprintf(out, 16, "1");
    else snprintf(out, 16, "1e%ld", e);
}

static void print_text(const compare_args* a, const veil_compare_stats* st, const extra_stats* x)
{
    printf("image          %s\n", a->image);
    printf("reference      %s (%dx%d)\n", a->reference, st->width, st->height);
    printf("rel_rmse       %.6g (floor %.6g%s)\n", st->rel_rmse, st->floor, a->floor > 0.0 ? "" : ", default");
    printf("rmse           %.6g\n", st->rmse);
    printf("max_abs        %.6g\n", st->max_abs);
    printf("off_5pct       %.6g (fraction of pixels more than %g%% off)\n", st->frac_off,
           100.0 * VEIL_COMPARE_OFF_FRACTION);
    if (isfinite(st->psnr_db)) printf("psnr_db        %.6g (peak: the reference's largest RGB value)\n", st->psnr_db);
    else printf("psnr_db        inf (identical RGB)\n");
    printf("alpha_max_abs  %.6g\n", st->alpha_max_abs);
    if (a->bin > 1) printf("bin            %d (means of %dx%d pixel blocks)\n", a->bin, a->bin, a->bin);
    if (isfinite(x->bias)) printf("mean_bias      %+.6g (mean RGB / reference's - 1)\n", x->bias);
    else printf("mean_bias      undefined (the reference's mean RGB is 0, the image's is not)\n");
    if (isfinite(x->noise))
        printf("noise          %.6g (reference's standard error, relative%s)\nrel_rmse_excess %.6g (noise taken out)\n",
               x->noise, x->bounded ? "; pixels whose error is a bound add none" : "", x->excess);
    if (isfinite(x->bias_se)) printf("mean_bias_se   %.6g (mean_bias's standard error from the reference's noise)\n", x->bias_se);
    if (a->heatmap) {
        char lo[16], hi[16], blue[16], magenta[16], yellow[16];
        decade(VEIL_COMPARE_HEATMAP_MIN, lo), decade(VEIL_COMPARE_HEATMAP_MAX, hi);
        decade(VEIL_COMPARE_HEATMAP_MIN * 10.0, blue), decade(VEIL_COMPARE_HEATMAP_MIN * 100.0, magenta);
        decade(VEIL_COMPARE_HEATMAP_MIN * 1000.0, yellow);
        printf("heatmap %s: relative error, log scale %s (black) .. %s (white); %s blue, %s magenta, %s yellow\n",
               a->heatmap, lo, hi, blue, magenta, yellow);
    }
}

static veil_result write_heatmap(const char* path, int w, int h, const float* rel, veil_error* err)
{
    size_t n = (size_t)w * (size_t)h; /* fits: the images of this size were allocated */
    unsigned char* rgb = malloc(n * 3);
    if (!rgb) return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory for a %dx%d heatmap", path, w, h);
    for (size_t i = 0; i < n; ++i) veil_compare_heatmap_colour(rel[i], rgb + i * 3);
    veil_result r = veil_write_png_rgb8(path, w, h, rgb, err);
    free(rgb);
    return r;
}

/* One channel of the reference's standard errors (or its stderr.bound): absent (*plane NULL, VEIL_OK), or
 * w x h finite values >= 0 (a standard error; stderr.bound: 0 or 1). Anything else is refused, naming the
 * file, the channel and the first bad pixel: a NaN or negative error made the noise NaN or smaller than it
 * is, and the excess error with it. */
static veil_result read_error_channel(const char* path, const char* name, int w, int h, float** plane, veil_error* err)
{
    int cw = 0, ch = 0;
    veil_error e = {0};
    veil_result r = veil_read_exr_channel(path, name, &cw, &ch, plane, &e);
    if (r == VEIL_ERR_INVALID) return VEIL_OK; /* absent */
    if (r != VEIL_OK) return veil_fail(err, r, "%s", e.msg);
    if (cw != w || ch != h) {
        free(*plane), *plane = NULL;
        return veil_fail(err, VEIL_ERR_INVALID, "%s: channel %s is %dx%d, the image %dx%d", path, name, cw, ch, w, h);
    }
    const int is_bound = strcmp(name, "stderr.bound") == 0;
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < (size_t)w * (size_t)h; ++i) {
        const float v = (*plane)[i];
        if (is_bound ? !(v == 0.0f || v == 1.0f) : !(isfinite(v) && v >= 0.0f))
            if (bad++ == 0) first = i;
    }
    if (!bad) return VEIL_OK;
    char got[32];
    veil_fail(err, VEIL_ERR_INVALID, "%s: channel %s at pixel (%zu, %zu) is %s: expected %s (%zu pixel%s so)", path,
              name, first % (size_t)w, first / (size_t)w, veil_number_text((*plane)[first], got, sizeof got),
              is_bound ? "0 or 1" : "a finite standard error >= 0", bad, bad == 1 ? "" : "s");
    free(*plane), *plane = NULL;
    return VEIL_ERR_INVALID;
}

/* The reference's standard errors, interleaved RGB in *se (NULL when it has none: all three or none of
 * stderr.R, .G, .B), with the pixels whose error is a bound (stderr.bound = 1: every sample was the same)
 * set to 0 and counted in *bounded: a bound is no measure of noise, so the noise is never overstated. */
static veil_result read_standard_errors(const char* path, int w, int h, float** se, size_t* bounded, veil_error* err)
{
    static const char* const names[3] = {"stderr.R", "stderr.G", "stderr.B"};
    float* planes[3] = {NULL, NULL, NULL};
    float* bound = NULL;
    veil_result r = VEIL_OK;
    int have = 0;
    for (int c = 0; c < 3 && r == VEIL_OK; ++c) {
        r = read_error_channel(path, names[c], w, h, &planes[c], err);
        have += planes[c] != NULL;
    }
    if (r == VEIL_OK && have != 0 && have != 3) {
        char list[64] = "";
        for (int c = 0; c < 3; ++c)
            if (planes[c]) snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", list[0] ? ", " : "", names[c]);
        r = veil_fail(err, VEIL_ERR_INVALID, "%s: has %s but not all of stderr.R, stderr.G, stderr.B", path, list);
    }
    if (r == VEIL_OK && have == 3) r = read_error_channel(path, "stderr.bound", w, h, &bound, err);
    const size_t n = (size_t)w * (size_t)h;
    if (r == VEIL_OK && have == 3 && !(*se = malloc(n * 3 * sizeof **se)))
        r = veil_fail(err, VEIL_ERR_OOM, "%s: out of memory for the standard errors", path);
    for (size_t i = 0; r == VEIL_OK && have == 3 && i < n; ++i) {
        const int b = bound && bound[i] != 0.0f;
        for (int c = 0; c < 3; ++c) (*se)[3 * i + (size_t)c] = b ? 0.0f : planes[c][i];
        *bounded += (size_t)b;
    }
    for (int c = 0; c < 3; ++c) free(planes[c]);
    free(bound);
    return r;
}

int veil_cmd_compare(int argc, char** argv)
{
    compare_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    const char* ins[2] = {a.image, a.reference};
    const char* outs[1] = {a.heatmap};
    const char* opts[1] = {"--heatmap"};
    rc = veil_cli_check_outputs(ins, 2, outs, opts, 1);
    if (rc != EXIT_OK) return rc;

    veil_error err = {0};
    int wa = 0, ha = 0, wb = 0, hb = 0;
    float *img = NULL, *ref = NULL, *rel = NULL;
    veil_result r = a.heatmap ? veil_cli_check_output_folder(a.heatmap, &err) : VEIL_OK;
    if (r == VEIL_OK) r = veil_read_exr(a.image, &wa, &ha, &img, &err);
    if (r == VEIL_OK) r = veil_read_exr(a.reference, &wb, &hb, &ref, &err);
    if (r == VEIL_OK && (wa != wb || ha != hb))
        r = veil_fail(&err, VEIL_ERR_INVALID, "%s is %dx%d but the reference %s is %dx%d: the sizes must match",
                      a.image, wa, ha, a.reference, wb, hb);
    if (r == VEIL_OK && a.heatmap) {
        size_t bytes = 0;
        if (!veil_mul_sizes((size_t)wa, (size_t)ha, sizeof(float), 1, &bytes) || !(rel = malloc(bytes)))
            r = veil_fail(&err, VEIL_ERR_OOM, "%s: out of memory for a %dx%d heatmap", a.heatmap, wa, ha);
    }
    veil_compare_stats st = {0};
    extra_stats x = {0.0, NAN, NAN, NAN, 0};
    float* se = NULL;
    if (r == VEIL_OK) {
        /* the reference's standard errors, when it has them */
        r = read_standard_errors(a.reference, wa, ha, &se, &x.bounded, &err);
    }
    if (r == VEIL_OK && a.bin > 1) {
        if (a.heatmap) r = veil_fail(&err, VEIL_ERR_INVALID, "--heatmap is per pixel: leave out --bin");
        float *bi = NULL, *br = NULL, *bse = NULL;
        if (r == VEIL_OK) r = veil_compare_bin(img, NULL, wa, ha, a.bin, &bi, NULL, &err);
        if (r == VEIL_OK) r = veil_compare_bin(ref, se, wa, ha, a.bin, &br, se ? &bse : NULL, &err);
        free(img), free(ref), free(se);
        img = bi, ref = br, se = bse;
        wa /= a.bin, ha /= a.bin;
    }
    if (r == VEIL_OK) {
        r = veil_compare_images(img, ref, wa, ha, a.floor, &st, rel, &err);
        if (r != VEIL_OK) {
            char tmp[VEIL_ERROR_MAX];
            snprintf(tmp, sizeof tmp, "%.500s (image) against %.500s (reference): %.1000s", a.image, a.reference,
                     err.msg);
            memcpy(err.msg, tmp, sizeof tmp);
        }
    }
    if (r == VEIL_OK) {
        x.bias = veil_compare_bias(img, ref, wa, ha);
        if (se) {
            x.noise = veil_compare_noise(ref, se, wa, ha, st.floor);
            double e = st.rel_rmse * st.rel_rmse - x.noise * x.noise;
            x.excess = e > 0.0 ? sqrt(e) : 0.0;
            x.bias_se = veil_compare_bias_se(img, ref, se, wa, ha);
        }
    }
    if (r == VEIL_OK && a.heatmap) r = write_heatmap(a.heatmap, wa, ha, rel, &err);
    free(se);
    free(img);
    free(ref);
    free(rel);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);

    if (a.json) print_json(&a, &st, &x);
    else print_text(&a, &st, &x);
    return EXIT_OK;
}
