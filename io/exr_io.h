/* veil — what io/exr.c (writing) and io/exr_read.c (reading) share
 * (internal): OpenEXRCore's error messages collected per thread, streams
 * over a file descriptor, channel names. */
#ifndef VEIL_EXR_IO_H
#define VEIL_EXR_IO_H

#include <openexr.h>
#include <stddef.h>
#include <stdint.h>

/* Error messages from OpenEXRCore.
 *
 * The library reports errors through a callback on the thread that caused
 * them. The callback must not call back into the library (some errors are
 * reported while the context's lock is held), so the messages are collected
 * in a thread-local sink set up around each of our calls: set
 * veil__exr_tls_msgs, restore it after. */
typedef struct exr_msgs {
    char text[1024];
    size_t len;
} exr_msgs;

extern _Thread_local exr_msgs* veil__exr_tls_msgs;

/* OpenEXRCore's compression for a VEIL_EXR_* (io/image.h). */
int veil__exr_compression_of(int compression);

/* The context initializer's error_handler_fn. */
void veil__exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char* msg);

/* The collected text, or OpenEXRCore's generic text for `code`. */
const char* veil__exr_reason(const exr_msgs* m, exr_result_t code);

/* Streams over a file descriptor we own (the context initializer's
 * user_data, read_fn, write_fn and size_fn). */
typedef struct fd_stream {
    int fd;
    int64_t size; /* reading: file size */
} fd_stream;

int64_t veil__exr_fd_write(exr_const_context_t ctxt, void* userdata, const void* buffer, uint64_t sz,
                           uint64_t offset, exr_stream_error_func_ptr_t error_cb);
int64_t veil__exr_fd_read(exr_const_context_t ctxt, void* userdata, void* buffer, uint64_t sz, uint64_t offset,
                          exr_stream_error_func_ptr_t error_cb);
int64_t veil__exr_fd_size(exr_const_context_t ctxt, void* userdata);

/* Index of `name` among names[0..n-1], or -1. */
int veil__exr_name_index(const char* const* names, int n, const char* name);

extern const char* const veil__exr_rgba_names[4]; /* R, G, B, A */

#endif
