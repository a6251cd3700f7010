#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gpu/gl_context.h"

int check_passed, check_failed;

int check_close(double a, double b, double abs_tol, double rel_tol)
{
    return isfinite(a) && fabs(a - b) <= abs_tol + rel_tol * fabs(b);
}

int check_finish(void)
{
    printf("%d passed, %d failed\n", check_passed, check_failed);
    return check_failed ? 1 : 0;
}

veil_gl* check_gpu_or_skip(void)
{
    veil_gl* gl = NULL;
    veil_error err = {0};
    if (veil_gl_create(&(veil_gl_desc){0}, &gl, &err) == VEIL_OK) return gl;
    const char* ci = getenv("CI");
    if (ci && strcmp(ci, "true") == 0) {
        fprintf(stderr, "FAIL: no GL 4.5 context under CI (the install script should provide llvmpipe): %s\n", err.msg);
        exit(1);
    }
    fprintf(stderr, "SKIPPED: no GL 4.5 context: %s\n", err.msg);
    exit(77);
}
