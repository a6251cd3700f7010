/* core/text.h: a file's bytes made safe for JSON and for a terminal (issue
 * 22, item 10). Each case's expected bytes are worked out by hand from RFC
 * 3629's table of well-formed sequences. */
#include <string.h>

#include "core/text.h"
#include "support/check.h"

static void utf8_case(const char* in, size_t n, const char* want)
{
    char out[64];
    veil_text_utf8(in, out, n);
    CHECK(strcmp(out, want) == 0, "utf8 of %zu bytes into %zu: got %zu bytes", strlen(in), n, strlen(out));
}

static void printable_case(const char* in, size_t n, int keep_lines, const char* want)
{
    char out[128];
    veil_text_printable(in, out, n, keep_lines);
    CHECK(strcmp(out, want) == 0, "printable: got '%s', expected '%s'", out, want);
}

int main(void)
{
    utf8_case("density", 64, "density");
    utf8_case("caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80", 64, "caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80"); /* 2, 3, 4 bytes */
    utf8_case("a\xFF" "b", 64, "a\xEF\xBF\xBD" "b");                                  /* never a UTF-8 byte */
    utf8_case("\x80", 64, "\xEF\xBF\xBD");                                           /* a lone continuation */
    utf8_case("\xC0\xAF", 64, "\xEF\xBF\xBD\xEF\xBF\xBD");                            /* overlong '/' */
    utf8_case("\xE0\x80\xAF", 64, "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD");            /* overlong, 3 bytes */
    utf8_case("\xED\xA0\x80", 64, "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD");            /* a surrogate, U+D800 */
    utf8_case("\xF4\x90\x80\x80", 64, "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD"); /* U+110000 */
    utf8_case("x\xE2\x82", 64, "x\xEF\xBF\xBD\xEF\xBF\xBD");                          /* cut short by the end */
    utf8_case("\x1B[1m", 64, "\x1B[1m");                                             /* JSON escapes controls itself */
    /* cut between characters only: 5 bytes of room hold "ab" and not half of the euro sign */
    utf8_case("ab\xE2\x82\xAC", 5, "ab");
    utf8_case("ab\xE2\x82\xAC", 6, "ab\xE2\x82\xAC");
    utf8_case("ab", 1, "");

    printable_case("density", 128, 0, "density");
    printable_case("den\x1B[31msity", 128, 0, "den\\x1B[31msity");
    printable_case("caf\xC3\xA9", 128, 0, "caf\xC3\xA9");
    printable_case("a\x7F" "b\xC2\x85" "c", 128, 0, "a\\x7Fb\\xC2\\x85c");          /* DEL, C1 NEL */
    printable_case("\xFF\xC0\xAF", 128, 0, "\\xFF\\xC0\\xAF");
    printable_case("line\none\ttab", 128, 0, "line\\x0Aone\\x09tab");
    printable_case("line\none\ttab", 128, 1, "line\none\ttab");
    printable_case("ab\x1B", 6, 0, "ab");                                            /* "\x1B" takes 4: not cut */
    return check_finish();
}
