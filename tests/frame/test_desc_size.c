/* How a description grows (frame/desc_size.h, include/veil.h "Descriptions
 * grow"), on a made-up description with two released layouts, as veil's
 * own descriptions will have once a field is appended:
 *   v1 {size; int a;}   v2 {size; int a; int b; double c;}
 * read by a library whose own layout is v2:
 *  - a v1 caller (size = sizeof v1, or 0) gets a, and b and c read as
 *    zero even though the bytes after its struct are junk: nothing past
 *    the v1 fields is read;
 *  - a v2 caller gets every field;
 *  - a size larger than v2, or between the layouts, is VEIL_ERR_INVALID
 *    with a message naming the sizes, and the output is all zero;
 *  - NULL is every default; the output's size is always the library's. */
#include <string.h>

#include "support/check.h"
#include "frame/desc_size.h"

typedef struct v1 {
    size_t size;
    int a;
} v1;
typedef struct v2 {
    size_t size;
    int a, b;
    double c;
} v2;

static const veil__desc_layout releases[] = {VEIL__DESC_LAYOUT(v1, a), VEIL__DESC_LAYOUT(v2, c)};
static const veil__desc_layouts layouts = {"veil_test", "v2_desc", releases, 2};

/* A caller's description at the start of a buffer whose rest is junk. */
static unsigned char buf[128];

static void put(const void* desc, size_t n)
{
    memset(buf, 0x5A, sizeof buf);
    memcpy(buf, desc, n);
}

static int all_zero(const v2* d)
{
    const unsigned char* p = (const unsigned char*)d;
    for (size_t i = 0; i < sizeof *d; ++i)
        if (p[i]) return 0;
    return 1;
}

int main(void)
{
    CHECK(sizeof(v1) < sizeof(v2) && releases[0].used < sizeof(v1),
          "the made-up layouts no longer exercise tail padding (v1 %zu bytes, fields end at %zu)", sizeof(v1),
          releases[0].used);
    veil_error err = {{0}};

    /* a v1 caller: its struct's tail padding and what follows are junk */
    v1 old;
    memset(&old, 0x5A, sizeof old);
    old.size = sizeof old, old.a = 7;
    put(&old, sizeof old);
    v2 d;
    CHECK(veil__desc_read(&layouts, buf, &d, &err) == VEIL_OK, "v1: %s", err.msg);
    CHECK(d.size == sizeof(v2) && d.a == 7 && d.b == 0 && d.c == 0.0, "v1 read as a=%d b=%d c=%g size %zu", d.a, d.b,
          d.c, d.size);

    old.size = 0; /* a zeroed description: the first layout */
    put(&old, sizeof old);
    CHECK(veil__desc_read(&layouts, buf, &d, &err) == VEIL_OK, "size 0: %s", err.msg);
    CHECK(d.size == sizeof(v2) && d.a == 7 && d.b == 0 && d.c == 0.0, "size 0 read as a=%d b=%d c=%g", d.a, d.b, d.c);

    v2 now = {.size = sizeof now, .a = 1, .b = 2, .c = 3.5};
    put(&now, sizeof now);
    CHECK(veil__desc_read(&layouts, buf, &d, &err) == VEIL_OK, "v2: %s", err.msg);
    CHECK(d.a == 1 && d.b == 2 && d.c == 3.5, "v2 read as a=%d b=%d c=%g", d.a, d.b, d.c);

    const size_t bad[] = {sizeof(v2) + 8, sizeof(v2) + 1000, sizeof(v1) + 4, 1, sizeof(size_t)};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        now.size = bad[i];
        put(&now, sizeof now);
        memset(&d, 0x77, sizeof d);
        memset(&err, 0, sizeof err);
        char text[40];
        snprintf(text, sizeof text, "v2_desc.size is %zu bytes", bad[i]);
        CHECK(veil__desc_read(&layouts, buf, &d, &err) == VEIL_ERR_INVALID, "size %zu accepted", bad[i]);
        CHECK(strstr(err.msg, "veil_test: ") == err.msg && strstr(err.msg, text), "size %zu: message: %s", bad[i],
              err.msg);
        CHECK(all_zero(&d), "size %zu: the output is not all zero", bad[i]);
    }
    char own[40];
    snprintf(own, sizeof own, "its own: %zu", sizeof(v2));
    CHECK(strstr(err.msg, own), "the last message does not name the library's size (%s): %s", own, err.msg);

    memset(&d, 0x77, sizeof d);
    CHECK(veil__desc_read(&layouts, NULL, &d, NULL) == VEIL_OK, "NULL");
    CHECK(d.size == sizeof(v2) && d.a == 0 && d.b == 0 && d.c == 0.0, "NULL read as a=%d b=%d c=%g", d.a, d.b, d.c);
    return check_finish();
}
