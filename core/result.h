/* veil — result codes and error messages, as the library uses them.
 *
 * The codes, the veil_error buffer, veil_result_name() and
 * veil_result_message() are public: include/veil/result.h, the one place the
 * codes are defined. This header adds the library's own helpers. Every
 * fallible library function returns a veil_result and, where the caller
 * passes one, fills a veil_error with a sentence that names the file, the
 * field and what was expected (or the EGL/GL call and its code). The library
 * never prints and never exits; only the CLI maps results to exit codes.
 */
#ifndef VEIL_RESULT_H
#define VEIL_RESULT_H

#include "../include/veil/result.h"

/* Formats into err->msg (err may be NULL) and returns `code`, so that
 * `return veil_fail(err, VEIL_ERR_IO, "%s: ...", path);` reads naturally. */
veil_result veil_fail(veil_error* err, veil_result code, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* x as a message shows it: "%g", or "not a number", "infinity",
 * "-infinity" (never "nan" or "inf"). Returns buf (n >= 32). */
const char* veil_number_text(double x, char* buf, size_t n);

/* True when n = a*b*c*d fits in size_t; writes the product to *out. */
int veil_mul_sizes(size_t a, size_t b, size_t c, size_t d, size_t* out);

#endif
