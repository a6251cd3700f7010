#define _POSIX_C_SOURCE 200809L
#include "tempfile.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* The registry: fixed slots, so that the handler reads only memory written
 * before it was published and calls only async-signal-safe functions. A
 * slot's data is written before its flag is set, and its flag cleared
 * before the slot is reused. */
static char g_paths[VEIL_TEMP_SLOTS][4352];
static volatile sig_atomic_t g_used[VEIL_TEMP_SLOTS];

/* the folder of numbered files */
static char g_dir[4352], g_dir_prefix[16], g_dir_suffix[16];
static int g_dir_digits;
static volatile long g_dir_count;
static volatile sig_atomic_t g_dir_used;

/* the folders made for outputs */
static char* const* volatile g_made;
static volatile size_t g_made_n;

/* the child */
static volatile sig_atomic_t g_child;

/* the thread that handles the signals, and what hold saved */
static pthread_t g_main;
static volatile sig_atomic_t g_have_main;
static sigset_t g_held_old;

/* Threads register and forget (a turntable's writer beside its renderer): the slots are claimed under
 * a lock, which the handler never takes (it only reads the flags). */
static pthread_mutex_t g_slots_lock = PTHREAD_MUTEX_INITIALIZER;

void veil_temp_register(const char* path)
{
    if (!path || strlen(path) >= sizeof g_paths[0]) return;
    pthread_mutex_lock(&g_slots_lock);
    for (int i = 0; i < VEIL_TEMP_SLOTS; ++i)
        if (!g_used[i]) {
            memcpy(g_paths[i], path, strlen(path) + 1);
            g_used[i] = 1;
            break;
        }
    pthread_mutex_unlock(&g_slots_lock);
}

void veil_temp_forget(const char* path)
{
    if (!path) return;
    pthread_mutex_lock(&g_slots_lock);
    for (int i = 0; i < VEIL_TEMP_SLOTS; ++i)
        if (g_used[i] && !strcmp(g_paths[i], path)) g_used[i] = 0;
    pthread_mutex_unlock(&g_slots_lock);
}

void veil_temp_register_folder(const char* dir, const char* prefix, int digits, const char* suffix)
{
    if (!dir || strlen(dir) >= sizeof g_dir || strlen(prefix) >= sizeof g_dir_prefix ||
        strlen(suffix) >= sizeof g_dir_suffix || digits < 0 || digits > 20)
        return;
    g_dir_used = 0;
    memcpy(g_dir, dir, strlen(dir) + 1);
    memcpy(g_dir_prefix, prefix, strlen(prefix) + 1);
    memcpy(g_dir_suffix, suffix, strlen(suffix) + 1);
    g_dir_digits = digits;
    g_dir_count = 0;
    g_dir_used = 1;
}

void veil_temp_folder_count(long count) { g_dir_count = count; }
void veil_temp_forget_folder(void) { g_dir_used = 0; }

void veil_temp_register_made_folders(char* const* dirs, size_t n)
{
    g_made_n = 0;
    g_made = dirs;
    g_made_n = n;
}

void veil_temp_forget_made_folders(void) { g_made_n = 0; }

void veil_temp_register_child(pid_t pid) { g_child = (sig_atomic_t)pid; }
void veil_temp_forget_child(void) { g_child = 0; }

void veil_temp_hold_signals(void)
{
    sigset_t s;
    sigemptyset(&s);
    sigaddset(&s, SIGINT);
    sigaddset(&s, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &s, &g_held_old);
}

void veil_temp_release_signals(void) { pthread_sigmask(SIG_SETMASK, &g_held_old, NULL); }

/* s + n bytes: dst (cap bytes) gets src appended at *k; 0 when it does not fit. */
static int append(char* dst, size_t cap, size_t* k, const char* src)
{
    for (; *src; ++src) {
        if (*k + 1 >= cap) return 0;
        dst[(*k)++] = *src;
    }
    dst[*k] = '\0';
    return 1;
}

/* v in decimal, at least `digits` digits, appended (snprintf is not async-signal-safe). */
static int append_number(char* dst, size_t cap, size_t* k, unsigned long v, int digits)
{
    char rev[32];
    int n = 0;
    do {
        rev[n++] = (char)('0' + v % 10);
        v /= 10;
    } while (v && n < 30);
    while (n < digits && n < 30) rev[n++] = '0';
    char num[32];
    for (int i = 0; i < n; ++i) num[i] = rev[n - 1 - i];
    num[n] = '\0';
    return append(dst, cap, k, num);
}

/* The child's group ended and the child reaped: SIGTERM, a grace period, then SIGKILL. */
static void end_child(void)
{
    pid_t pid = (pid_t)g_child;
    if (pid <= 0) return;
    if (kill(-pid, SIGTERM) != 0) kill(pid, SIGTERM); /* not yet its own group: the child itself */
    const struct timespec tick = {0, 10 * 1000 * 1000};
    for (int t = 0; t < VEIL_TEMP_CHILD_GRACE_MS / 10; ++t) {
        if (waitpid(pid, NULL, WNOHANG) != 0) return; /* reaped, or not ours to wait for */
        nanosleep(&tick, NULL);
    }
    if (kill(-pid, SIGKILL) != 0) kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
}

static void cleanup(int sig)
{
    if (g_have_main && !pthread_equal(pthread_self(), g_main)) {
        /* a driver's thread: the files' thread cleans up (it may be writing one right now) */
        pthread_kill(g_main, sig);
        return;
    }
    end_child();
    for (int i = 0; i < VEIL_TEMP_SLOTS; ++i)
        if (g_used[i]) unlink(g_paths[i]);
    if (g_dir_used) {
        for (long k = 0; k < g_dir_count; ++k) {
            char name[4400];
            size_t n = 0;
            if (append(name, sizeof name, &n, g_dir) && append(name, sizeof name, &n, "/") &&
                append(name, sizeof name, &n, g_dir_prefix) &&
                append_number(name, sizeof name, &n, (unsigned long)k, g_dir_digits) &&
                append(name, sizeof name, &n, g_dir_suffix))
                unlink(name);
        }
        rmdir(g_dir);
    }
    for (size_t i = g_made_n; i > 0; --i) rmdir(g_made[i - 1]); /* the empty ones go */
    _exit(128 + sig);
}

void veil_temp_install_signal_cleanup(void)
{
    g_main = pthread_self();
    g_have_main = 1;
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
        /* registered before it exists: a signal between open and a later registration would leave it */
        veil_temp_register(tmp);
        int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) {
            *tmp_out = tmp;
            return fd;
        }
        int e = errno;
        veil_temp_forget(tmp);
        errno = e;
        if (errno != EEXIST) break;
    }
    int e = errno;
    free(tmp);
    errno = e;
    return -1;
}
