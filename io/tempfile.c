#define _POSIX_C_SOURCE 200809L
#include "tempfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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
