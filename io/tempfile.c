#define _POSIX_C_SOURCE 200809L
#include "tempfile.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The registry: fixed slots, so that the handler reads only static memory
 * and calls only unlink and _exit (async-signal-safe). A slot's path is
 * written before its flag is set, and its flag cleared before the slot is
 * reused. */
static char g_paths[VEIL_TEMP_SLOTS][4352];
static volatile sig_atomic_t g_used[VEIL_TEMP_SLOTS];

void veil_temp_register(const char* path)
{
    if (!path || strlen(path) >= sizeof g_paths[0]) return;
    for (int i = 0; i < VEIL_TEMP_SLOTS; ++i)
        if (!g_used[i]) {
            memcpy(g_paths[i], path, strlen(path) + 1);
            g_used[i] = 1;
            return;
        }
}

void veil_temp_forget(const char* path)
{
    if (!path) return;
    for (int i = 0; i < VEIL_TEMP_SLOTS; ++i)
        if (g_used[i] && !strcmp(g_paths[i], path)) g_used[i] = 0;
}

static void cleanup(int sig)
{
    for (int i = 0; i < VEIL_TEMP_SLOTS; ++i)
        if (g_used[i]) unlink(g_paths[i]);
    _exit(128 + sig);
}

void veil_temp_install_signal_cleanup(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = cleanup;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);
    sigaddset(&sa.sa_mask, SIGTERM);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

int veil_open_temp_beside(const char* path, char** tmp_out)
{
    static atomic_uint counter;
    struct stat st;
    *tmp_out = NULL;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        errno = 0;
        return -1;
    }
    size_t n = strlen(path) + 48;
    char* tmp = malloc(n);
    if (!tmp) {
        errno = ENOMEM;
        return -1;
    }
    for (int attempt = 0; attempt < 100; ++attempt) {
        unsigned k = atomic_fetch_add(&counter, 1u);
        snprintf(tmp, n, "%s.tmp%ld.%u", path, (long)getpid(), k);
        int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) {
            veil_temp_register(tmp);
            *tmp_out = tmp;
            return fd;
        }
        if (errno != EEXIST) break;
    }
    int e = errno;
    free(tmp);
    errno = e;
    return -1;
}
