#include "frame_pattern.h"

#include <stdio.h>
#include <string.h>

/* Finds the pattern's number: [*at, *at + *len) and its least digits; 1, 0 or -1 as veil_frame_pattern_kind. */
static int find_number(const char* p, size_t* at, size_t* len, int* digits)
{
    int found = 0;
    for (size_t i = 0; p[i];) {
        if (p[i] == '#') {
            size_t j = i;
            while (p[j] == '#') ++j;
            if (found++) return -1;
            *at = i, *len = j - i, *digits = (int)(j - i);
            i = j;
        } else if (p[i] == '%') {
            if (p[i + 1] == '%') {
                i += 2;
                continue;
            }
            size_t j = i + 1;
            int d = 0;
            if (p[j] == '0' && p[j + 1] >= '1' && p[j + 1] <= '9' && p[j + 2] == 'd') d = p[j + 1] - '0', j += 2;
            else if (p[j] != 'd') return -1;
            if (found++) return -1;
            *at = i, *len = j + 1 - i, *digits = d;
            i = j + 1;
        } else {
            ++i;
        }
    }
    return found;
}

int veil_frame_pattern_kind(const char* pattern)
{
    size_t at, len;
    int digits;
    return find_number(pattern, &at, &len, &digits);
}

veil_result veil_frame_pattern_path(const char* pattern, long frame, char* out, size_t n, veil_error* err)
{
    size_t at = 0, len = 0;
    int digits = 0;
    if (find_number(pattern, &at, &len, &digits) != 1)
        return veil_fail(err, VEIL_ERR_INVALID, "'%s': a frame file name needs the frame number once, as #### "
                         "or %%04d", pattern);
    size_t k = 0;
    int fits = 1;
    for (size_t i = 0; pattern[i] && fits; ++i) {
        if (i == at) {
            /* written straight into out, its length asked first: the pattern's run of # sets the least
             * digits and may be longer than any buffer of its own (a fixed one overflowed at 32 #);
             * the magnitude as unsigned, so that -LONG_MIN does not overflow */
            unsigned long mag = frame < 0 ? 0UL - (unsigned long)frame : (unsigned long)frame;
            const char* sign = frame < 0 ? "-" : "";
            int w = snprintf(NULL, 0, "%s%0*lu", sign, digits, mag);
            if (w < 0 || k + (size_t)w >= n) fits = 0;
            else snprintf(out + k, n - k, "%s%0*lu", sign, digits, mag), k += (size_t)w;
            i += len - 1;
            continue;
        }
        if (pattern[i] == '%' && pattern[i + 1] == '%') ++i; /* a literal '%' */
        if (k + 1 >= n) fits = 0;
        else out[k++] = pattern[i];
    }
    if (!fits || n == 0)
        return veil_fail(err, VEIL_ERR_LIMIT, "'%s': frame %ld's file name is too long", pattern, frame);
    out[k] = '\0';
    return VEIL_OK;
}

