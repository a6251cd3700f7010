/* veil — result codes and error messages (public).
 *
 * Every fallible veil function returns a veil_result (VEIL_OK is 0) and,
 * where the caller passes one, fills a veil_error with a sentence that names
 * the file, the field and what was expected (or the EGL/GL call and its
 * code). The library never prints and never exits.
 *
 * The table below is the one place the codes are defined: it yields the enum,
 * the name (veil_result_name) and a generic message (veil_result_message).
 *
 * VEIL_API, defined here because every public header includes this one,
 * marks each function libveil.so exports: the library is compiled with
 * hidden visibility, so a function without it is not part of the ABI.
 */
#ifndef VEIL_PUBLIC_RESULT_H
#define VEIL_PUBLIC_RESULT_H

#include <stddef.h>
#include <stdint.h>

#ifndef VEIL_API
#if defined(__GNUC__) || defined(__clang__)
#define VEIL_API __attribute__((visibility("default")))
#else
#define VEIL_API
#endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* X(name, value, generic message) */
#define VEIL_RESULTS(X)                                                        \
    X(VEIL_OK, 0, "success")                                                   \
    X(VEIL_ERR_IO, 1, "a file could not be read or written")                   \
    X(VEIL_ERR_PARSE, 2, "malformed input")                                    \
    X(VEIL_ERR_INVALID, 3, "invalid argument or field value")                  \
    X(VEIL_ERR_OOM, 4, "out of memory")                                        \
    X(VEIL_ERR_LIMIT, 5, "a size exceeds a limit")                             \
    X(VEIL_ERR_GPU, 6, "GPU or driver failure")                                \
    X(VEIL_ERR_SHADER, 7, "shader compile or link failed")                     \
    X(VEIL_ERR_CANCELLED, 8, "cancelled by the caller")

typedef int32_t veil_result;
enum {
#define VEIL__ENUM(name, value, msg) name = value,
    VEIL_RESULTS(VEIL__ENUM)
#undef VEIL__ENUM
};

#define VEIL_ERROR_MAX 2048

/* A message buffer; zero-initialise it. */
typedef struct veil_error {
    char msg[VEIL_ERROR_MAX];
} veil_error;

VEIL_API const char* veil_result_name(veil_result r);    /* "VEIL_ERR_IO" */
VEIL_API const char* veil_result_message(veil_result r); /* generic text */

#ifdef __cplusplus
}
#endif

#endif
