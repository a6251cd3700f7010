/* veil — writing a file all or nothing: open a temporary beside the target,
 * write it, then rename it over the target (or unlink it on failure). Used
 * by every writer, so a failed run never leaves a partial output file. */
#ifndef VEIL_TEMPFILE_H
#define VEIL_TEMPFILE_H

/* Creates "<path>.tmp<pid>.<n>" with O_EXCL and mode 0666 (less the umask,
 * like any new file) and returns its descriptor; *tmp_out receives its
 * malloc'd name. An existing target that is not a regular file (a
 * directory, /dev/null, a FIFO) is refused, since renaming over it would
 * replace it. Returns -1 with errno set, or with errno 0 for that refusal. */
int veil_open_temp_beside(const char* path, char** tmp_out);

/* Files being written that a SIGINT or SIGTERM must not leave behind
 * (temporaries, a command's staged outputs): at most VEIL_TEMP_SLOTS at a
 * time. veil_open_temp_beside registers its temporary itself; a writer
 * calls veil_temp_forget once it has renamed or removed it. */
#define VEIL_TEMP_SLOTS 16
void veil_temp_register(const char* path);
void veil_temp_forget(const char* path);
/* Installs handlers for SIGINT and SIGTERM that remove every registered
 * file and exit with 128 + the signal (130, 143), as shells report it. */
void veil_temp_install_signal_cleanup(void);

#endif
