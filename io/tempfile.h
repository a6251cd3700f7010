/* veil — writing a file all or nothing: open a temporary beside the target,
 * write it, then rename it over the target (or unlink it on failure). Used
 * by every writer, so a failed run never leaves a partial output file.
 *
 * And what a SIGINT or SIGTERM must not leave behind: the temporaries and
 * staged outputs being written, a folder of numbered scratch files (the
 * movie's frames), the folders a run made for its outputs, and a child
 * process (ffmpeg). The handler uses only data registered beforehand and
 * async-signal-safe calls (kill, waitpid, nanosleep, unlink, rmdir, _exit);
 * it runs on the thread that installed it (a signal delivered to another
 * thread, a GL driver's worker, is passed on to it), so it never races the
 * writes of that thread. */
#ifndef VEIL_TEMPFILE_H
#define VEIL_TEMPFILE_H

#include <stddef.h>
#include <sys/types.h>

/* Creates "<path>.tmp<pid>.<n>" with O_EXCL and mode 0666 (less the umask,
 * like any new file) and returns its descriptor; *tmp_out receives its
 * malloc'd name. An existing target that is not a regular file (a
 * directory, /dev/null, a FIFO) is refused, since renaming over it would
 * replace it. Returns -1 with errno set, or with errno 0 for that refusal. */
int veil_open_temp_beside(const char* path, char** tmp_out);

/* Files being written that a SIGINT or SIGTERM must not leave behind
 * (temporaries, a command's staged outputs): at most VEIL_TEMP_SLOTS at a
 * time. veil_open_temp_beside registers its temporary itself (before it
 * exists: removing a name not yet made is harmless); a writer calls
 * veil_temp_forget once it has renamed or removed it. */
#define VEIL_TEMP_SLOTS 16
void veil_temp_register(const char* path);
void veil_temp_forget(const char* path);

/* One folder of numbered files, "<dir>/<prefix><k, at least `digits`
 * digits><suffix>" for 0 <= k < count: a signal removes those files, then
 * the folder. Register it once made, and raise the count (as files are
 * made) with veil_temp_folder_count. prefix and suffix: at most 15 bytes. */
void veil_temp_register_folder(const char* dir, const char* prefix, int digits, const char* suffix);
void veil_temp_folder_count(long count);
void veil_temp_forget_folder(void);

/* Folders a run made for its outputs (cli/cli_util.h): a signal removes
 * those of them that are empty, the last made first. The array stays the
 * caller's and must outlive the registration. */
void veil_temp_register_made_folders(char* const* dirs, size_t n);
void veil_temp_forget_made_folders(void);

/* A child process, the leader of its own process group (setpgid): a signal
 * ends its group (SIGTERM; SIGKILL after VEIL_TEMP_CHILD_GRACE_MS) and
 * reaps it before the files are removed, so that it cannot write into them
 * again. */
#define VEIL_TEMP_CHILD_GRACE_MS 2000
void veil_temp_register_child(pid_t pid);
void veil_temp_forget_child(void);

/* Holds SIGINT and SIGTERM back on the calling thread until the matching
 * release (they are delivered then): for making something and registering
 * it as one step (a fork and its child's registration, a folder). Not
 * nested. */
void veil_temp_hold_signals(void);
void veil_temp_release_signals(void);

/* Installs handlers for SIGINT and SIGTERM that end the registered child,
 * remove every registered file and folder, and exit with 128 + the signal
 * (130, 143), as shells report it. Call it from the thread that writes the
 * files (the CLI's main thread), before other threads are made. */
void veil_temp_install_signal_cleanup(void);

#endif
