/* veil — what the EXR writer and reader share (io/exr_io.h). */
#define _POSIX_C_SOURCE 200809L

#include "exr_io.h"

#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

const char* const veil__exr_rgba_names[4] = {"R", "G", "B", "A"};

_Thread_local exr_msgs* veil__exr_tls_msgs;

static void msgs_append(exr_msgs* m, const char* s)
{
    if (!m || !s || !*s) return;
    size_t cap = sizeof m->text;
    if (m->len + 1 >= cap) return;
    int n = snprintf(m->text + m->len, cap - m->len, "%s%s", m->len ? "; " : "", s);
    if (n < 0) return;
    m->len += (size_t)n;
    if (m->len >= cap) m->len = cap - 1;
}

void veil__exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char* msg)
{
    (void)ctxt;
    msgs_append(veil__exr_tls_msgs, msg && *msg ? msg : exr_get_default_error_message(code));
}

const char* veil__exr_reason(const exr_msgs* m, exr_result_t code)
{
    if (m->len) return m->text;
    return exr_get_default_error_message(code);
}

static int offset_fits(uint64_t off, uint64_t len)
{
    /* off + len must be representable as a non-negative off_t */
    const uint64_t max = (sizeof(off_t) >= 8) ? (uint64_t)INT64_MAX : (uint64_t)INT32_MAX;
    return off <= max && len <= max - off;
}

/* pwrite or pread of sz bytes at offset, in pieces; a read stops short only
 * at end of file. One of wbuf and rbuf is given. */
static int64_t fd_io(exr_const_context_t ctxt, fd_stream* s, const void* wbuf, void* rbuf, uint64_t sz,
                     uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    const int writing = rbuf == NULL;
    const exr_result_t code = writing ? EXR_ERR_WRITE_IO : EXR_ERR_READ_IO;
    const char* what = writing ? "write" : "read";
    uint64_t done = 0;
    if (!offset_fits(offset, sz)) {
        if (error_cb) error_cb(ctxt, code, "%s past the largest file offset", what);
        return -1;
    }
    while (done < sz) {
        uint64_t left = sz - done;
        size_t n = left > (1u << 30) ? (size_t)(1u << 30) : (size_t)left;
        off_t at = (off_t)(offset + done);
        ssize_t r = writing ? pwrite(s->fd, (const unsigned char*)wbuf + done, n, at)
                            : pread(s->fd, (unsigned char*)rbuf + done, n, at);
        if (r < 0 && errno == EINTR) continue;
        if (r == 0 && !writing) break; /* end of file: the library decides whether that is an error */
        if (r <= 0) {
            if (error_cb)
                error_cb(ctxt, code, "cannot %s %" PRIu64 " bytes at offset %" PRIu64 ": %s", what, sz, offset,
                         r < 0 ? strerror(errno) : "no progress");
            return -1;
        }
        done += (uint64_t)r;
    }
    return (int64_t)done;
}

int64_t veil__exr_fd_write(exr_const_context_t ctxt, void* userdata, const void* buffer, uint64_t sz,
                        uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    return fd_io(ctxt, userdata, buffer, NULL, sz, offset, error_cb);
}

int64_t veil__exr_fd_read(exr_const_context_t ctxt, void* userdata, void* buffer, uint64_t sz, uint64_t offset,
                       exr_stream_error_func_ptr_t error_cb)
{
    return fd_io(ctxt, userdata, NULL, buffer, sz, offset, error_cb);
}

int64_t veil__exr_fd_size(exr_const_context_t ctxt, void* userdata)
{
    (void)ctxt;
    return ((fd_stream*)userdata)->size;
}

int veil__exr_name_index(const char* const* names, int n, const char* name)
{
    for (int i = 0; name && i < n; ++i)
        if (strcmp(names[i], name) == 0) return i;
    return -1;
}
