/* veil turntable's review outputs: a contact sheet PNG of the frames and a
 * movie (MP4 or GIF) through the ffmpeg program. Both read the frames'
 * EXR files back, so they can be made by a later run over frames that
 * other processes (a farm's shards) rendered. */
#define _POSIX_C_SOURCE 200809L
#include "review.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include "cli_util.h"
#include "io/image.h"
#include "io/tempfile.h"

/* The frame's EXR as 8-bit sRGB (the PNG preview's tone curve), newly malloc'd. */
static veil_result frame_rgb8(const char* exr, int* w, int* h, unsigned char** rgb, veil_error* err)
{
    float* rgba = NULL;
    *rgb = NULL;
    veil_result r = veil_read_exr(exr, w, h, &rgba, err);
    if (r != VEIL_OK) return r;
    size_t n = (size_t)*w * (size_t)*h;
    *rgb = malloc(n * 3);
    if (!*rgb) {
        free(rgba);
        return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory", exr);
    }
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            (*rgb)[3 * i + c] = (unsigned char)floorf(veil_srgb_encode(veil_tonemap(rgba[4 * i + c])) * 255.0f + 0.5f);
    free(rgba);
    return VEIL_OK;
}

veil_result veil_review_contact_sheet(const char* const* frames, int n, const char* out, veil_error* err)
{
    if (n < 1) return veil_fail(err, VEIL_ERR_INVALID, "%s: a contact sheet of no frames", out);
    int cols = (int)ceil(sqrt((double)n)), rows = (n + cols - 1) / cols;
    int w0 = 0, h0 = 0, tw = 0, th = 0, gap = 2, sw = 0, sh = 0;
    unsigned char* sheet = NULL;
    veil_result r = VEIL_OK;
    for (int k = 0; k < n && r == VEIL_OK; ++k) {
        int w, h;
        unsigned char* rgb;
        r = frame_rgb8(frames[k], &w, &h, &rgb, err);
        if (r != VEIL_OK) break;
        if (k == 0) { /* thumbnails at most 320 wide, the sheet at most 4096 */
            w0 = w, h0 = h;
            int limit = (4096 - gap * (cols + 1)) / cols;
            tw = w < 320 ? w : 320;
            tw = tw < limit ? tw : limit;
            tw = tw < 1 ? 1 : tw;
            th = (int)((double)h * tw / w + 0.5);
            th = th < 1 ? 1 : th;
            sw = cols * tw + (cols + 1) * gap, sh = rows * th + (rows + 1) * gap;
            sheet = calloc((size_t)sw * (size_t)sh, 3);
            if (!sheet) r = veil_fail(err, VEIL_ERR_OOM, "%s: out of memory for a %dx%d sheet", out, sw, sh);
        } else if (w != w0 || h != h0) {
            r = veil_fail(err, VEIL_ERR_INVALID, "%s: %dx%d, not %dx%d as the first frame", frames[k], w, h, w0, h0);
        }
        /* each thumbnail pixel: the mean of the frame's pixels it covers (a box filter) */
        int x0 = gap + (k % cols) * (tw + gap), y0 = gap + (k / cols) * (th + gap);
        for (int ty = 0; ty < th && r == VEIL_OK; ++ty)
            for (int tx = 0; tx < tw; ++tx) {
                int ax = tx * w / tw, bx = (tx + 1) * w / tw, ay = ty * h / th, by = (ty + 1) * h / th;
                bx = bx > ax ? bx : ax + 1, by = by > ay ? by : ay + 1;
                unsigned sum[3] = {0, 0, 0}, cnt = 0;
                for (int y = ay; y < by && y < h; ++y)
                    for (int x = ax; x < bx && x < w; ++x, ++cnt)
                        for (int c = 0; c < 3; ++c) sum[c] += rgb[3 * ((size_t)y * w + x) + c];
                for (int c = 0; c < 3; ++c)
                    sheet[3 * ((size_t)(y0 + ty) * sw + x0 + tx) + c] = (unsigned char)(cnt ? (sum[c] + cnt / 2) / cnt : 0);
            }
        free(rgb);
    }
    if (r == VEIL_OK) r = veil_write_png_rgb8(out, sw, sh, sheet, err);
    free(sheet);
    return r;
}

/* name on PATH: its path into out (n bytes), 1; else 0. */
static int find_program(const char* name, char* out, size_t n)
{
    const char* path = getenv("PATH");
    if (!path) return 0;
    while (*path) {
        const char* end = strchr(path, ':');
        size_t len = end ? (size_t)(end - path) : strlen(path);
        int w = snprintf(out, n, "%.*s/%s", (int)len, path, name);
        if (w > 0 && (size_t)w < n && access(out, X_OK) == 0) return 1;
        path += len + (end ? 1 : 0);
    }
    return 0;
}

int veil_review_find_ffmpeg(char* out, size_t n) { return find_program("ffmpeg", out, n); }

void veil_review_movie_names(const char* out, char* staged, size_t ns, char* frames_dir, size_t nd)
{
    const char* dot = strrchr(out, '.');
    const char* slash = strrchr(out, '/');
    if (!dot || (slash && dot < slash)) dot = "";
    snprintf(staged, ns, "%s.veil-staged%ld%s", out, (long)getpid(), dot); /* ffmpeg picks the format by it */
    snprintf(frames_dir, nd, "%s.veil-frames%ld", out, (long)getpid());
}

/* The frames' PNGs in the folder: "f000000.png", ... (ffmpeg's image-sequence input "f%06d.png"). */
#define FRAME_PREFIX "f"
#define FRAME_DIGITS 6
#define FRAME_SUFFIX ".png"

/* ffmpeg on the folder's frames into staged; VEIL_OK when it exits 0. */
static veil_result run_ffmpeg(const char* ffmpeg, const char* dir, int gif, double fps, const char* staged,
                              const char* out, veil_error* err)
{
    char pattern[4400], rate[32];
    snprintf(pattern, sizeof pattern, "%s/" FRAME_PREFIX "%%0%dd" FRAME_SUFFIX, dir, FRAME_DIGITS);
    snprintf(rate, sizeof rate, "%g", fps);
    const char* argv_mp4[] = {ffmpeg, "-nostdin", "-y", "-loglevel", "error", "-framerate", rate, "-i", pattern,
                              "-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2", "-pix_fmt", "yuv420p", staged, NULL};
    const char* argv_gif[] = {ffmpeg, "-nostdin", "-y", "-loglevel", "error", "-framerate", rate, "-i", pattern,
                              "-vf", "split[a][b];[a]palettegen[p];[b][p]paletteuse", staged, NULL};
    /* the child in a process group of its own, registered before a signal can be handled: the handler
     * (io/tempfile.h) ends the group and reaps it before it removes the files ffmpeg writes */
    veil_temp_hold_signals();
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid == 0) {
        setpgid(0, 0);
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
#ifdef __linux__
        prctl(PR_SET_PDEATHSIG, SIGTERM); /* and if veil is killed outright (SIGKILL), ffmpeg ends too */
        if (getppid() != parent) _exit(127); /* it was, before that */
#endif
        veil_temp_release_signals();
        execv(ffmpeg, (char* const*)(gif ? argv_gif : argv_mp4));
        _exit(127);
    }
    if (pid > 0) {
        setpgid(pid, pid); /* as the child does: whichever runs first */
        veil_temp_register_child(pid);
    }
    veil_temp_release_signals();
    int status = 0;
    veil_result r = VEIL_OK;
    int waited = pid > 0 ? (int)waitpid(pid, &status, 0) : -1;
    veil_temp_forget_child();
    if (waited < 0)
        r = veil_fail(err, VEIL_ERR_IO, "%s: cannot run %s: %s", out, ffmpeg, strerror(errno));
    else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        r = veil_fail(err, VEIL_ERR_IO, "%s: ffmpeg failed (%s %d); its messages are above", out,
                      WIFEXITED(status) ? "exit" : "signal", WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
    return r;
}

/* Removes the folder's first n frames, then the folder. */
static void remove_frames(const char* dir, int n)
{
    for (int k = 0; k < n; ++k) {
        char png[4400];
        snprintf(png, sizeof png, "%s/" FRAME_PREFIX "%0*d" FRAME_SUFFIX, dir, FRAME_DIGITS, k);
        unlink(png);
    }
    rmdir(dir);
}

veil_result veil_review_movie(const char* const* frames, int n, double fps, const char* out, veil_error* err)
{
    char ffmpeg[4096];
    if (!find_program("ffmpeg", ffmpeg, sizeof ffmpeg))
        return veil_fail(err, VEIL_ERR_IO, "%s: a movie needs the ffmpeg program (Debian package ffmpeg), and there is "
                         "none on PATH; the frames are written", out);
    const char* dot = strrchr(out, '.');
    int gif = dot && !strcmp(dot, ".gif");
    if (!dot || (!gif && strcmp(dot, ".mp4") && strcmp(dot, ".mov") && strcmp(dot, ".mkv")))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: a movie is .mp4, .mov, .mkv or .gif", out);
    /* the frames as numbered PNGs in a folder beside the movie, ffmpeg's image-sequence input; the folder,
     * its frames and the staged movie registered, for a signal to remove them (io/tempfile.h) */
    char dir[4200], staged[4200];
    veil_review_movie_names(out, staged, sizeof staged, dir, sizeof dir);
    veil_temp_hold_signals();
    int made = mkdir(dir, 0700) == 0;
    int e = errno;
    if (made) veil_temp_register_folder(dir, FRAME_PREFIX, FRAME_DIGITS, FRAME_SUFFIX);
    veil_temp_release_signals();
    if (!made) return veil_fail(err, VEIL_ERR_IO, "%s: cannot make %s: %s", out, dir, strerror(e));
    veil_result r = VEIL_OK;
    int written = 0;
    for (int k = 0; k < n && r == VEIL_OK; ++k) {
        int w, h;
        unsigned char* rgb;
        r = frame_rgb8(frames[k], &w, &h, &rgb, err);
        if (r == VEIL_OK) {
            char png[4400];
            snprintf(png, sizeof png, "%s/" FRAME_PREFIX "%0*d" FRAME_SUFFIX, dir, FRAME_DIGITS, k);
            veil_temp_folder_count(k + 1); /* before it exists, as the temporaries */
            written = k + 1;
            r = veil_write_png_rgb8(png, w, h, rgb, err);
        }
        free(rgb);
    }
    veil_temp_register(staged); /* ffmpeg writes it */
    if (r == VEIL_OK) r = run_ffmpeg(ffmpeg, dir, gif, fps, staged, out, err);
    if (r == VEIL_OK && rename(staged, out) != 0)
        r = veil_fail(err, VEIL_ERR_IO, "%s: cannot move %s into place: %s", out, staged, strerror(errno));
    unlink(staged);
    veil_temp_forget(staged);
    remove_frames(dir, written);
    veil_temp_forget_folder();
    return r;
}
