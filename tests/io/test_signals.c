/* SIGINT and SIGTERM during a write (issue 12, defect 6): the temporary a
 * writer holds (io/tempfile.h) is removed and the process exits 130 / 143.
 * A child opens a temporary beside a target, as every writer does, and
 * signals itself while it is open; the parent checks the exit status and
 * that neither the temporary nor the target exists.
 *
 * And what a movie leaves (issue 22, item 7): a folder of numbered frames,
 * the folders a run made for its outputs, and a child process in its own
 * group (ffmpeg), with the signal delivered to another thread than the one
 * that registered them (a GL driver's worker): all removed, the child
 * ended and reaped, exit 143. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "support/check.h"
#include "io/tempfile.h"

static void* raise_term(void* unused)
{
    (void)unused;
    raise(SIGTERM); /* to this thread only */
    return NULL;
}

/* The child of the movie case: registers, starts its own child, has another thread signalled. */
static void movie_child(const char* dir, int fd)
{
    veil_temp_install_signal_cleanup();
    static char made0[300], made1[300], frames[300];
    snprintf(made0, sizeof made0, "%s/made", dir);
    snprintf(made1, sizeof made1, "%s/made/sub", dir);
    snprintf(frames, sizeof frames, "%s/frames", dir);
    static char* made[2] = {made0, made1};
    if (mkdir(made0, 0777) || mkdir(made1, 0777) || mkdir(frames, 0700)) _exit(2);
    veil_temp_register_made_folders(made, 2);
    veil_temp_register_folder(frames, "f", 6, ".png");
    for (int k = 0; k < 3; ++k) {
        char png[400];
        snprintf(png, sizeof png, "%s/f%06d.png", frames, k);
        FILE* f = fopen(png, "wb");
        if (!f) _exit(2);
        fclose(f);
        veil_temp_folder_count(k + 1);
    }
    veil_temp_hold_signals();
    pid_t pid = fork();
    if (pid == 0) { /* ffmpeg's stand-in: its own group, waiting to be ended */
        setpgid(0, 0);
        signal(SIGTERM, SIG_DFL);
        veil_temp_release_signals();
        for (;;) pause();
    }
    setpgid(pid, pid);
    veil_temp_register_child(pid);
    veil_temp_release_signals();
    if (write(fd, &pid, sizeof pid) != sizeof pid) _exit(2);
    pthread_t t;
    if (pthread_create(&t, NULL, raise_term, NULL) != 0) _exit(2);
    for (int i = 0; i < 100; ++i) sleep(1); /* the handler ends this */
    _exit(3);
}

int main(void)
{
    char dir[] = "/tmp/veil_signals_XXXXXX";
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    const int sigs[2] = {SIGINT, SIGTERM};
    for (int k = 0; k < 2; ++k) {
        char target[256], tmp_path[512] = "";
        snprintf(target, sizeof target, "%s/out%d.exr", dir, k);
        int fds[2];
        CHECK(pipe(fds) == 0, "pipe");
        pid_t pid = fork();
        if (pid == 0) {
            close(fds[0]);
            veil_temp_install_signal_cleanup();
            char* tmp = NULL;
            int fd = veil_open_temp_beside(target, &tmp);
            if (fd < 0) _exit(2);
            if (write(fd, "partial", 7) != 7) _exit(2);
            /* tell the parent the temporary's name, then be interrupted mid-write */
            if (write(fds[1], tmp, strlen(tmp) + 1) < 0) _exit(2);
            raise(sigs[k]);
            _exit(3); /* not reached */
        }
        close(fds[1]);
        ssize_t n = read(fds[0], tmp_path, sizeof tmp_path - 1);
        close(fds[0]);
        int status = 0;
        waitpid(pid, &status, 0);
        CHECK(n > 0 && strstr(tmp_path, "out"), "the child did not open a temporary");
        CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 128 + sigs[k], "signal %d: status %d (exited %d, code %d)",
              sigs[k], status, WIFEXITED(status), WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        CHECK(access(tmp_path, F_OK) != 0, "signal %d: the temporary %s was left behind", sigs[k], tmp_path);
        CHECK(access(target, F_OK) != 0, "signal %d: a target was written", sigs[k]);
    }
    int fds[2];
    CHECK(pipe(fds) == 0, "pipe");
    pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        movie_child(dir, fds[1]);
    }
    close(fds[1]);
    pid_t grandchild = 0;
    ssize_t got = read(fds[0], &grandchild, sizeof grandchild);
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    CHECK(got == sizeof grandchild && grandchild > 0, "the child did not start its own child");
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 143, "movie: status %d (exited %d, code %d)", status,
          WIFEXITED(status), WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    char path[300];
    snprintf(path, sizeof path, "%s/frames", dir);
    CHECK(access(path, F_OK) != 0, "the folder of frames %s was left behind", path);
    snprintf(path, sizeof path, "%s/made", dir);
    CHECK(access(path, F_OK) != 0, "the folders made for the outputs were left behind (%s)", path);
    /* reaped by the handler: no process, not even a zombie (kill(0) succeeds on a zombie) */
    CHECK(got == sizeof grandchild && kill(grandchild, 0) != 0 && errno == ESRCH, "the child %ld is still there",
          (long)grandchild);
    if (got == sizeof grandchild && grandchild > 0) kill(grandchild, SIGKILL);
    rmdir(dir);
    return check_finish();
}
