/* veil — text from files, made safe to print (text.h). */
#include "text.h"

#include <stdio.h>
#include <string.h>

/* The length of the UTF-8 character at s (1..4), or 0 when s does not start
 * a valid one; *cp its code point. */
static size_t utf8_char(const unsigned char* s, unsigned* cp)
{
    const unsigned c = s[0];
    size_t len;
    unsigned v, min;
    if (c < 0x80) {
        *cp = c;
        return 1;
    } else if (c >= 0xC2 && c <= 0xDF) {
        len = 2, v = c & 0x1F, min = 0x80;
    } else if (c >= 0xE0 && c <= 0xEF) {
        len = 3, v = c & 0x0F, min = 0x800;
    } else if (c >= 0xF0 && c <= 0xF4) {
        len = 4, v = c & 0x07, min = 0x10000;
    } else {
        return 0;
    }
    for (size_t i = 1; i < len; ++i) {
        if ((s[i] & 0xC0) != 0x80) return 0; /* also stops at the NUL */
        v = v << 6 | (s[i] & 0x3F);
    }
    if (v < min || v > 0x10FFFF || (v >= 0xD800 && v <= 0xDFFF)) return 0;
    *cp = v;
    return len;
}

/* Appends len bytes when they fit with the NUL; 0 when they do not. */
static int put(char* out, size_t n, size_t* at, const void* bytes, size_t len)
{
    if (*at + len + 1 > n) return 0;
    memcpy(out + *at, bytes, len);
    *at += len;
    return 1;
}

void veil_text_utf8(const char* in, char* out, size_t n)
{
    static const char replacement[] = "\xEF\xBF\xBD";
    const unsigned char* s = (const unsigned char*)in;
    size_t at = 0;
    while (*s) {
        unsigned cp;
        size_t len = utf8_char(s, &cp);
        if (!(len ? put(out, n, &at, s, len) : put(out, n, &at, replacement, 3))) break;
        s += len ? len : 1;
    }
    out[at] = '\0';
}

void veil_text_printable(const char* in, char* out, size_t n, int keep_lines)
{
    const unsigned char* s = (const unsigned char*)in;
    size_t at = 0;
    while (*s) {
        unsigned cp = 0;
        size_t len = utf8_char(s, &cp);
        int control = len == 0 || cp < 0x20 || (cp >= 0x7F && cp <= 0x9F);
        if (keep_lines && (cp == '\n' || cp == '\t')) control = 0;
        int ok = 1;
        if (!control) {
            ok = put(out, n, &at, s, len);
        } else {
            /* every byte of it, so that the file's bytes can be read back */
            size_t bytes = len ? len : 1;
            char esc[4 * 4 + 1];
            for (size_t i = 0; i < bytes; ++i) snprintf(esc + 4 * i, 5, "\\x%02X", s[i]);
            ok = put(out, n, &at, esc, 4 * bytes);
        }
        if (!ok) break;
        s += len ? len : 1;
    }
    out[at] = '\0';
}
