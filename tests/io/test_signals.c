/* SIGINT and SIGTERM during a write (issue 12, defect 6): the temporary a
 * writer holds (io/tempfile.h) is removed and the process exits 130 / 143.
 * A child opens a temporary beside a target, as every writer does, and
 * signals itself while it is open; the parent checks the exit status and
 * that neither the temporary nor the target exists. */
#define _POSIX_C_SOURCE 200809L
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "support/check.h"
#include "io/tempfile.h"

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
    rmdir(dir);
    return check_finish();
}
