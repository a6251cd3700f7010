/* veil — text from files, made safe to print.
 *
 * A grid's name, class or transform type is whatever bytes a file holds:
 * not always UTF-8 (then `veil info --json` was not JSON) and sometimes
 * control characters (then the table sent escape sequences to the
 * terminal). Both functions write a NUL-terminated string of at most n - 1
 * bytes (n > 0), cut only between characters. */
#ifndef VEIL_TEXT_H
#define VEIL_TEXT_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Valid UTF-8 (RFC 3629: no overlong forms, no surrogates, at most
 * U+10FFFF) copied as it is; each byte of anything else becomes U+FFFD. For
 * JSON, whose writer escapes the control characters itself. */
void veil_text_utf8(const char* in, char* out, size_t n);

/* For a terminal: printable UTF-8 copied; C0 and C1 control characters,
 * DEL and each byte that is not UTF-8 written as \xNN. With keep_lines,
 * '\n' and '\t' are kept (a message of several lines). */
void veil_text_printable(const char* in, char* out, size_t n, int keep_lines);

#ifdef __cplusplus
}
#endif

#endif
