/* veil — what the subcommands share: messages, exit codes, option parsing. */
#ifndef VEIL_CLI_UTIL_H
#define VEIL_CLI_UTIL_H

#include "core/result.h"
#include "run_files.h"
#include "scene/scene.h"

enum { EXIT_OK = 0, EXIT_INPUT = 1, EXIT_USAGE = 2, EXIT_GPU = 3 };

/* "veil: " + fmt with arg + a hint to --help, on stderr; returns EXIT_USAGE. */
int veil_cli_usage_error(const char* fmt, const char* arg);
/* EXIT_GPU for GPU and shader errors, EXIT_INPUT for the rest. */
int veil_cli_exit_code(veil_result r);
/* Prints err's message (or r's generic one); returns veil_cli_exit_code(r). */
int veil_cli_fail(veil_result r, const veil_error* err);
/* "what went wrong" -> "file: what went wrong". */
void veil_cli_prefix_error(veil_error* err, const char* file);
/* A whole decimal integer in [lo, hi] / a number in [lo, hi]: 1, else 0. */
int veil_cli_parse_int(const char* s, long lo, long hi, long* out);
int veil_cli_parse_float(const char* s, float lo, float hi, float* out);
/* --shutter: "OPEN,CLOSE" (frames relative to the frame, each in [-4, 4],
 * open <= close) sets *set = 1 and sh; "off" sets *set = -1. 1, else 0. */
int veil_cli_parse_shutter(const char* s, int* set, float sh[2]);
/* The EXR output's options, for every command that writes one: --exr-type half|float, --exr-compression
 * NAME (none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab), --dwa-level L (in (0, 1000]). 1 when s is
 * one of them, its value v parsed into f (*rc EXIT_USAGE with the message printed on a bad or missing
 * value, else -1); 0 when s is none of them. */
struct veil_exr_format;
int veil_cli_exr_option(const char* s, const char* v, struct veil_exr_format* f, int* rc);
/* What --shutter asked for, over the scene's camera.shutter (set 0: the scene's). */
void veil_cli_apply_shutter(veil_scene* scene, int set, const float sh[2]);
/* VEIL_ERR_IO naming the path when the folder it would be written to does
 * not exist (checked before any work, so nothing is written half). */
veil_result veil_cli_check_output_folder(const char* path, veil_error* err);

/* The files of a run checked before any work (cli/run_files.h): EXIT_OK,
 * or EXIT_USAGE with the clash printed (naming both files), or EXIT_INPUT
 * with the error (a name too long, a folder that cannot be looked into). */
int veil_cli_check_run(const veil_run_file* files, int n, const veil_frame_range* range);

/* The run's inputs: the scene file `path` ("the scene") and each file s
 * reads (veil_scene_files: "medium.sources[i].file", the environment's
 * "lights[i].file"): a sequence's pattern
 * followed over the run's frames (per_frame), or its file of frame 1 (the
 * commands that render that frame of it). In one block with room for
 * `extra` more entries after the *n made; free() it. NULL: out of memory. */
veil_run_file* veil_cli_scene_inputs(const char* path, const veil_scene* s, int per_frame, int extra, int* n);

/* The folders of a run's outputs, made before the first frame as mkdir -p
 * does (film tools make a frames/ folder), and each checked writable:
 * VEIL_ERR_IO naming the option and the folder otherwise. Those it made
 * are listed (and registered, io/tempfile.h: a signal removes them when
 * empty). `range`: the frames this process writes (a shard's). */
typedef struct veil_cli_folders {
    char** made;
    size_t n, cap;
} veil_cli_folders;
veil_result veil_cli_make_folders(const veil_run_file* files, int n, const veil_frame_range* range,
                                  veil_cli_folders* made, veil_error* err);
/* ok: the folders stay; else those made that are still empty are removed,
 * the last made first (a failed run leaves no folder it made for nothing). */
void veil_cli_folders_done(veil_cli_folders* made, int ok);

/* Usage checks of the output paths before any work (exit 2, naming the
 * option): none empty, no two the same file (the same path, or an existing
 * file under two names), none an input file (a scene, a frame: the run
 * would overwrite what it reads), none an existing directory: the run's
 * files as veil_cli_check_run checks them, each a file of its own. inputs
 * and outputs: n strings each (16 in all at most), NULL entries skipped;
 * names: each output's option ("-o", "--png"). Returns EXIT_OK, EXIT_USAGE
 * or EXIT_INPUT (message printed). */
int veil_cli_check_outputs(const char* const* inputs, int n_in, const char* const* outputs, const char* const* names,
                           int n_out);

/* All or nothing for a command that writes several files: each writer
 * writes a staging file beside its target ("<target>.veil-staged<pid>"),
 * and only when all are written are they renamed over the targets; on a
 * failure the staged files are removed and every existing target is left
 * as it was. */
typedef struct veil_cli_outputs {
    const char* target[4];
    char staged[4][4200];
    int count;
} veil_cli_outputs;
/* The staging path to write target to (its name kept in `o`); NULL and
 * VEIL_ERR_IO when the target exists and is not a regular file. Stage each
 * file just before writing it. */
const char* veil_cli_stage(veil_cli_outputs* o, const char* target, veil_error* err);
/* Renames every staged file over its target (VEIL_ERR_IO naming it when one
 * cannot be, after which the rest are removed), or, with ok == 0, removes
 * them. */
veil_result veil_cli_commit(veil_cli_outputs* o, int ok, veil_error* err);

#endif
