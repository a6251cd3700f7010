/* veil — the command-line tool. main() dispatches each command to its file:
 *
 *   veil render      a scene to an EXR (and a PNG preview)       cli/render.c
 *   veil turntable   frames on an orbit, a sequence, farm shards cli/turntable.c
 *   veil reference   the CPU path tracer's ground truth          cli/reference.c
 *   veil compare     an image against a reference                cli/compare.c
 *   veil fog         the medium added to a frame made elsewhere  cli/fog.c
 *   veil info        the grids of an OpenVDB or NanoVDB file     cli/info.c
 *   veil gpuinfo     the EGL device and GL context veil gets     cli/gpuinfo.c
 *   veil rbf generate  a seeded random particle file             cli/rbf.c
 *   veil --help | --version
 *
 * Each command's usage is usage_text below, the README's command block
 * ("## The command") line for line; ctest cli_docs fails when the two, the
 * dispatch, this list or a command's parsed options drift apart.
 * Exit codes: 0 success, 1 bad input (scene, file), 2 usage, 3 GPU/driver.
 * Messages go to stderr; the written paths and the time to stdout.
 */
#include <stdio.h>
#include <string.h>

#include "cli_util.h"
#include "io/tempfile.h"
#include "io/vdb.h"
#include "commands.h"

static const char* usage_text =
    "usage: veil render SCENE.json -o OUT.exr [--png OUT.png] [--width W] [--height H]\n"
    "                   [--quality Q] [--step S] [--od-spacing A[,B]] [--seed N] [--method M]\n"
    "                   [--turntable N] [--shutter O,C|off] [--aovs] [--deep OUT.exr] [--deep-samples N]\n"
    "                   [--exr-type half|float] [--exr-compression C [--dwa-level L]] [--stats] [--explain]\n"
    "       veil turntable SCENE.json -o OUT.####.exr [--frames N | --range A-B[xS]] [--png OUT.####.png]\n"
    "                      [--axis X,Y,Z] [--start DEG] [--degrees DEG] [--elevation DEG] [--shard I/N]\n"
    "                      [--skip-existing] [--skip-missing] [--quality Q] [--step S] [--seed N]\n"
    "                      [--width W] [--height H] [--method M] [--contact-sheet OUT.png]\n"
    "                      [--movie OUT.mp4|gif] [--fps F] [--shutter O,C|off] [--aovs] [--deep OUT.####.exr]\n"
    "                      [--deep-samples N] [--exr-type half|float] [--exr-compression C [--dwa-level L]]\n"
    "                      [--stats] [--explain] [--quiet | --progress]\n"
    "       veil reference SCENE.json -o REF.exr --spp N [--max-order K] [--width W] [--height H]\n"
    "                      [--seed N] [--threads T] [--light-sampling distance|mis]\n"
    "                      [--background backdrop|lights]\n"
    "       veil compare A.exr REF.exr [--heatmap OUT.png] [--floor F] [--bin B] [--json]\n"
    "       veil fog FRAME.exr --scene SCENE.json -o OUT.exr [--png OUT.png] [--depth-channel NAME]\n"
    "                [--depth-is z|distance] [--no-occluders] [--aovs] [--exr-type half|float]\n"
    "                [--exr-compression C [--dwa-level L]] [--stats]\n"
    "       veil info FILE.vdb [--json]\n"
    "       veil gpuinfo\n"
    "       veil rbf generate -o OUT --count N --seed S --bounds x0,y0,z0,x1,y1,z1\n"
    "                         --radius r0,r1 --amplitude c0,c1 [--noise-scale L] [--noise-octaves K]\n"
    "                         [--noise-amount A] [--format json|binary]\n"
    "       veil --help | --version\n"
    "\n"
    "render   renders a scene (docs/scene-format.md) to an HDR EXR (R, G, B, A = 1 - mean\n"
    "         transmittance) and optionally a tone-mapped sRGB PNG preview.\n"
    "  -o OUT.exr     output EXR (required)\n"
    "  --png OUT.png  also write a preview PNG\n"
    "  --width W, --height H  override the scene camera's image size (1..16384)\n"
    "  --quality Q    draft, default, high or max (else the scene's \"quality\"): the march\n"
    "                 step, the optical-depth method and its grids' spacing together\n"
    "                 (docs/performance.md has each rung's time and error)\n"
    "  --step S       ray-march step in voxels (default: the rung's, 0.5 at default)\n"
    "  --seed N       jitter seed (default 0)\n"
    "  --method M     optical-depth propagation: light-space (the default: the first four\n"
    "                 lights in grids aligned with them, one prefix sum a column, a point\n"
    "                 or spot light's on the faces of a cube around it; other lights as\n"
    "                 semi-lagrangian), semi-lagrangian, sweep, jacobi-corrected,\n"
    "                 jacobi (the published scheme)\n"
    "  --od-spacing A[,B]  light-space grids: nodes A voxels apart across the light and\n"
    "                 B along it (default: the rung's, 0.5,4 at default; B = A if left out;\n"
    "                 point and spot lights: 1.4 A across, B/2 along)\n"
    "  --shutter O,C|off  the camera's shutter, frames around the frame (e.g. -0.25,0.25):\n"
    "                 vdb sources with a \"velocity\" are motion-blurred over it; off: none\n"
    "                 (default: the scene's camera.shutter)\n"
    "  --turntable N  N frames with the camera orbiting the look-at point about the\n"
    "                 up axis, written as OUT_0000.exr ... (volume and optical depth\n"
    "                 are computed once and reused: see --stats)\n"
    "  --aovs         also write the AOV channels T.R, T.G, T.B (transmittance), P (density\n"
    "                 integral along the ray), single.R, single.G, single.B (single scattering\n"
    "                 without the background), depth (mean distance of the first\n"
    "                 interaction, m; 0 where the ray meets no medium), multiple.volume.R/G/B\n"
    "                 and multiple.screen.R/G/B (each multiple-scattering estimate apart), Z\n"
    "                 (depth along the view axis, as compositors read it; +inf: no medium)\n"
    "  --deep OUT.exr also write a deep EXR (scanline, ZIPS): each pixel's ray as volumetric\n"
    "                 samples R, G, B, A, Z, ZBack (Z, ZBack along the view axis, m) that\n"
    "                 flatten to the image less the background, for holdouts in a compositor\n"
    "  --deep-samples N  at most N samples a pixel (1..64; default the scene's\n"
    "                 \"deep\": {\"samples\"}, else 8): adjacent ones merged, which loses only\n"
    "                 depth (--stats: the holdout error of the merge)\n"
    "  --exr-type half|float  the EXR's pixels as 16-bit half or 32-bit float (default float);\n"
    "                 distances (Z, depth) and P stay float in a half file\n"
    "  --exr-compression C  none, rle, zips, zip (the default), piz, pxr24, b44, b44a, dwaa\n"
    "                 or dwab (the last five lossy; --dwa-level L, default 45); the chunks are\n"
    "                 compressed on every core (VEIL_EXR_THREADS=N: on N)\n"
    "  --stats        print each stage's wall time in milliseconds, whether it ran, was\n"
    "                 cached or skipped, and why\n"
    "  --explain      print which stages run on which frame and why, without rendering\n"
    "                 (no GPU needed; -o may be left out)\n"
    "turntable  renders frames of a scene, the camera orbiting its look-at point: frame f of\n"
    "         a range of n at --start + --degrees * i / n (i its index; default a full turn\n"
    "         about the camera's up axis, or --axis), raised by --elevation first. OUT holds\n"
    "         the frame number once, as #### (digits at least) or %04d. The volume and\n"
    "         optical depth are computed once; each frame's image depends only on the scene\n"
    "         and its number (jitter seeded per frame), so shards make the same bytes.\n"
    "  --frames N     frames 1..N (default 1); --range A-B[xS]: A, A+S, ... up to B\n"
    "  --shard I/N    only every N-th frame of the range, starting with its I-th (a farm task)\n"
    "  --skip-existing  leave frames whose files exist (frames are renamed into place whole)\n"
    "  --deep OUT.####.exr  also each frame's deep EXR (as render's --deep; --deep-samples N)\n"
    "  --contact-sheet OUT.png, --movie OUT.mp4|.mov|.mkv|.gif (--fps F, default 24)  made from\n"
    "                 every frame of the range once they are all written (by this run or the\n"
    "                 farm's other shards: rerun with --skip-existing); the movie through the\n"
    "                 ffmpeg program (Debian package ffmpeg)\n"
    "  --quiet, --progress  no status line, or one even when stderr is not a terminal (frame,\n"
    "                 stage, time left); by default only on a terminal\n"
    "  --skip-missing   a vdb source whose file holds #### (a sequence, one file a frame) may\n"
    "                 lack some frames: skip those frames (without it, a missing one is an error)\n"
    "reference  renders a scene with the CPU path tracer (reference/pathtracer.h), the\n"
    "         ground truth the GPU path is measured against. The EXR holds R, G, B, A and\n"
    "         the per-pixel standard error of each mean (stderr.R, stderr.G, stderr.B).\n"
    "  --spp N        samples per pixel (2..1000000, required)\n"
    "  --max-order K  scatterings counted: 1 single scattering (the GPU marcher's\n"
    "                 quantity), 0 all (default 0)\n"
    "  --seed N       (default 0); the same seed gives the same image on any thread count\n"
    "  --threads T    worker threads (default: one per core)\n"
    "  --light-sampling distance|mis  distances toward point and spot lights: mis\n"
    "                 (default) adds equiangular samples, combined with distance\n"
    "                 sampling at every vertex; distance: distance sampling alone\n"
    "  --background backdrop|lights  backdrop (default): the background is seen through\n"
    "                 the medium and lights nothing, as veil render has it; lights: it is\n"
    "                 a constant sky around the scene, seen by every path that escapes the\n"
    "                 medium after scattering (the phase function samples it)\n"
    "compare  compares image A against reference REF (both EXR, same size): relative\n"
    "         RMSE (denominator floored at --floor, default 1% of REF's mean), max abs\n"
    "         error, fraction of pixels more than 5% off, PSNR, mean bias (mean RGB /\n"
    "         REF's - 1); with REF's stderr channels also its noise and the error with\n"
    "         that noise taken out (rel_rmse_excess).\n"
    "  --bin B        compare means of BxB pixel blocks (the reference's noise falls B x)\n"
    "  --floor F      the denominator's floor, absolute (default 1% of REF's mean RGB)\n"
    "  --heatmap OUT.png  per-pixel relative error as a colour map, log scale:\n"
    "                 black 1e-4 (and 0), blue 1e-3, magenta 1e-2, yellow 1e-1, white 1\n"
    "  --json         print the numbers as JSON (psnr_db null for identical RGB)\n"
    "fog      adds the scene's medium to a frame rendered elsewhere with the scene's\n"
    "         camera: FRAME's surfaces are attenuated, glow and blur through the medium\n"
    "         (screen-space multiple scattering), lit medium in front of them added.\n"
    "  --depth-channel NAME  the depth channel (default: the first of Z, depth.Z,\n"
    "                 depth, distance); +inf where nothing was hit\n"
    "  --depth-is z|distance  depth along the view axis (default) or along the ray\n"
    "  --no-occluders the frame's surfaces neither shadow the medium nor absorb its\n"
    "                 light (by default they do, as far as the frame shows them)\n"
    "info     lists the grids of an OpenVDB (or NanoVDB .nvdb) file: name, class, value\n"
    "         type, active voxels, index and world bounding boxes, voxel size and transform,\n"
    "         and whether render copies it at its own voxels, holds it sparse or resamples it.\n"
    "  --json         print them as JSON instead of a table\n"
    "gpuinfo  prints the EGL platform and device, GL vendor, renderer, version and\n"
    "         the largest 3D texture. VEIL_DEVICE=software forces llvmpipe.\n"
    "rbf generate  writes a seeded random particle file (docs/particles.md) for an\n"
    "         \"rbf\" source's \"file\": N particles (0..10000000), centres uniform in\n"
    "         the box, radius (1/sharpness, m) and amplitude uniform in their ranges;\n"
    "         the same seed (0..2^53-1) gives the same file on every machine.\n"
    "  --noise-amount A  0..1 (default 0): amplitude *= (1-A) + A*fbm(centre/L)\n"
    "  --noise-scale L   fBm feature size in metres (default 1)\n"
    "  --noise-octaves K fBm octaves, 1..16 (default 4)\n"
    "  --format F     json or binary (default: json when OUT ends in .json)\n"
    "\n"
    "exit codes: 0 success, 1 bad input, 2 usage, 3 GPU or driver failure\n";

int main(int argc, char** argv)
{
    veil_temp_install_signal_cleanup(); /* SIGINT, SIGTERM: no temporary left, exit 130, 143 */
    veil_vdb_limit_reads(1);            /* a corrupt VDB fails instead of taking gigabytes */
    if (argc < 2) {
        fputs(usage_text, stderr);
        return EXIT_USAGE;
    }
    const char* cmd = argv[1];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        fputs(usage_text, stdout);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "--version")) {
        printf("veil %s\n", VEIL_VERSION);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "render")) return veil_cmd_render(argc, argv);
    if (!strcmp(cmd, "turntable")) return veil_cmd_turntable(argc, argv);
    if (!strcmp(cmd, "info")) return veil_cmd_info(argc, argv);
    if (!strcmp(cmd, "rbf")) return veil_cmd_rbf(argc, argv);
    if (!strcmp(cmd, "reference")) return veil_cmd_reference(argc, argv);
    if (!strcmp(cmd, "compare")) return veil_cmd_compare(argc, argv);
    if (!strcmp(cmd, "fog")) return veil_cmd_fog(argc, argv);
    if (!strcmp(cmd, "gpuinfo")) return veil_cmd_gpuinfo(argc, argv);
    return veil_cli_usage_error("unknown command '%s'", cmd);
}
