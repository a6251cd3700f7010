/* veil tests — a tiny assertion harness.
 *
 * CHECK(cond, fmt, ...) records a failure with a message and goes on;
 * check_finish() prints "N passed, N failed" and returns the exit code.
 * check_gpu_or_skip() makes a GL 4.5 context or exits 77 (skipped), except
 * under CI=true where it fails: in CI the install script provides llvmpipe.
 */
#ifndef VEIL_TEST_CHECK_H
#define VEIL_TEST_CHECK_H

#include <stdio.h>

#include "gpu/gl_context.h"

extern int check_passed, check_failed;

#define CHECK(cond, ...)                                                        \
    do {                                                                        \
        if (cond) {                                                             \
            ++check_passed;                                                     \
        } else {                                                                \
            ++check_failed;                                                     \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                       \
            fputc('\n', stderr);                                                \
        }                                                                       \
    } while (0)

/* |a - b| <= abs_tol + rel_tol * |b| */
int check_close(double a, double b, double abs_tol, double rel_tol);

int check_finish(void);

/* Returns a context, or exits 77 / 1 (CI) after printing why. */
veil_gl* check_gpu_or_skip(void);

#endif
