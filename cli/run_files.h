/* veil — the files of a run, checked against each other before any work
 * (issue 22). A run reads files (the scene, its VDB and particle files,
 * each frame's file of a sequence) and writes files (each frame of a range
 * under one or two patterns, a contact sheet, a movie, and the staging
 * names they are written under before the rename). No file it writes may
 * be a file it reads, and no two files it writes may be one.
 *
 * Two names are one file when they name the same directory entry: the real
 * path of the folder (symbolic links and "..": realpath(3); a folder not
 * made yet: its nearest existing ancestor's real path and the rest taken
 * as written) and the file's name; or, for files that exist, when they are
 * the same file (device and inode: a symbolic link to it, a hard link).
 *
 * The cost: every file of every frame is named, hashed (FNV-1a, 64 bits)
 * and stat'ed once; a 16-byte record each, and one more for each that
 * exists, sorted to find equal hashes, which are then compared by name (or
 * identity). A day of film (2 073 600 frames, an EXR and a PNG each) is
 * 4.1 million records, 66 MB (133 MB when every frame exists already).
 * Pure otherwise: nothing is written, nothing printed. */
#ifndef VEIL_CLI_RUN_FILES_H
#define VEIL_CLI_RUN_FILES_H

#include "core/result.h"
#include "frame/frames.h"

/* How a file's name follows the frame. */
typedef enum veil_run_naming {
    VEIL_RUN_ONE = 0,   /* `path` itself, one file for the run */
    VEIL_RUN_PATTERN,   /* a frame pattern (scene/frame_pattern.h): frame f's file is its f + offset */
    VEIL_RUN_NUMBERED   /* render --turntable's: "_NNNN" before the extension (frame/plan.h veil_frame_path) */
} veil_run_naming;

typedef struct veil_run_file {
    const char* what;      /* how messages name it: "-o", "the scene", "medium.sources[0].file" */
    const char* path;      /* the file, or its pattern */
    veil_run_naming naming;
    long offset;           /* VEIL_RUN_PATTERN: the pattern's frame is the run's frame + offset */
    int writes;            /* 1: the run writes it; 0: reads it */
    const char* staged;    /* writes: the suffix of the name it is first written under (".veil-staged<pid>"),
                              checked against the inputs; NULL: none */
    int scratch;           /* writes: a name the run makes for itself (the movie's folder of frames), which
                              must not exist yet */
} veil_run_file;

typedef enum veil_run_problem {
    VEIL_RUN_FINE = 0,
    VEIL_RUN_EMPTY,        /* an output's name is empty */
    VEIL_RUN_DIRECTORY,    /* an output is a directory ("d/", "d/.", or one that exists) */
    VEIL_RUN_NOT_REGULAR,  /* an output exists and is not a regular file (a FIFO, a device) */
    VEIL_RUN_EXISTS,       /* a scratch name exists */
    VEIL_RUN_NOT_FOLDER,   /* an output's folder is a file (`detail`) */
    VEIL_RUN_SAME_NAME,    /* two files of the run are one directory entry */
    VEIL_RUN_SAME_FILE,    /* two names of one existing file (links, hard links) */
    VEIL_RUN_STAGED        /* an output's staging name is an input */
} veil_run_problem;

/* What is wrong: the first output (in the order below) with a problem of
 * its own (empty, a directory, ...), else the clash whose later file comes
 * first in that order (then whose earlier file does): the files of one
 * name for the whole run, then each frame of the range, files[] in order
 * within each. */
typedef struct veil_run_clash {
    veil_run_problem problem;
    int a, b;            /* files[] of the output at fault, and of what it clashes with (-1: none) */
    int a_framed, b_framed;
    long frame_a, frame_b;
    char path_a[4096];   /* a's file of frame_a */
    char path_b[4096];
    char detail[4096];   /* NOT_FOLDER: the folder that is a file; STAGED: a's staging name */
} veil_run_clash;

/* Checks files[0 .. n) over the frames of range (NULL: none of them may
 * follow the frame). use_fs: 1 as above; 0 by name only, each path
 * normalised as written ("a/./b/../c" is "a/c"), touching no file (the fuzz
 * target). clash->problem is VEIL_RUN_FINE when all is well. Errors: a
 * name too long (VEIL_ERR_LIMIT), a folder that cannot be looked into
 * (VEIL_ERR_IO), out of memory. */
veil_result veil_run_files_check(const veil_run_file* files, int n, const veil_frame_range* range, int use_fs,
                                 veil_run_clash* clash, veil_error* err);

/* f's file of `frame` (ignored for VEIL_RUN_ONE). */
veil_result veil_run_file_path(const veil_run_file* f, long frame, char* out, size_t n, veil_error* err);

/* The clash as a sentence, naming both files, options and frames:
 * "-o 'f10.exr' (frame 10) and --png 'f10.exr' (frame 9) are one file: ...". */
void veil_run_clash_text(const veil_run_file* files, const veil_run_clash* c, char* out, size_t n);

#endif
