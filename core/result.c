#include "result.h"

#include <math.h>

#include <stdarg.h>
#include <stdio.h>

veil_result veil_fail(veil_error* err, veil_result code, const char* fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return code;
}

const char* veil_result_name(veil_result r)
{
    switch (r) {
#define VEIL__NAME(name, value, msg) case name: return #name;
        VEIL_RESULTS(VEIL__NAME)
#undef VEIL__NAME
    }
    return "VEIL_ERR_UNKNOWN";
}

const char* veil_result_message(veil_result r)
{
    switch (r) {
#define VEIL__MSG(name, value, msg) case name: return msg;
        VEIL_RESULTS(VEIL__MSG)
#undef VEIL__MSG
    }
    return "unknown result code";
}

int veil_mul_sizes(size_t a, size_t b, size_t c, size_t d, size_t* out)
{
    size_t n = a;
    const size_t f[3] = {b, c, d};
    for (int i = 0; i < 3; ++i) {
        if (f[i] != 0 && n > SIZE_MAX / f[i]) return 0;
        n *= f[i];
    }
    *out = n;
    return 1;
}

const char* veil_number_text(double x, char* buf, size_t n)
{
    if (isnan(x)) snprintf(buf, n, "not a number");
    else if (isinf(x)) snprintf(buf, n, "%sinfinity", x < 0 ? "-" : "");
    else snprintf(buf, n, "%g", x);
    return buf;
}
