/* veil — reading a public description that can grow (include/veil.h, "Descriptions grow").
 *
 * Each veil_X_desc opens with a size_t `size`. frame/api.c keeps a frozen
 * copy of each released layout of each description, oldest first, each
 * larger than the one before. veil__desc_read checks the caller's size
 * against them and copies the fields of the caller's layout (up to the end
 * of its last field, not its tail padding, where a later layout may have
 * put a field) into a zeroed description of the library's own layout, so a
 * field the caller's layout does not have reads as zero, its default.
 * size 0 stands for the first layout. A size larger than the library's
 * layout, or one that is no layout's size, is VEIL_ERR_INVALID and nothing
 * past the size field is read.
 */
#ifndef VEIL_FRAME_DESC_SIZE_H
#define VEIL_FRAME_DESC_SIZE_H

#include <stddef.h>
#include <string.h>

#include "../core/result.h"

/* One released layout: its sizeof (what a caller's `size` holds) and the
 * end of its last field. */
typedef struct veil__desc_layout {
    size_t size, used;
} veil__desc_layout;
#define VEIL__DESC_LAYOUT(type, last_field) \
    {sizeof(type), offsetof(type, last_field) + sizeof(((type*)0)->last_field)}

typedef struct veil__desc_layouts {
    const char* fn;                  /* the public function reading it, for messages: "veil_render" */
    const char* type;                /* "veil_render_desc" */
    const veil__desc_layout* layout; /* oldest first; the last is the library's own */
    int count;
} veil__desc_layouts;

/* Copies *src (NULL: every field default) into dst, a description of
 * the library's own layout (a size_t first), and sets dst's size to the
 * library's. On failure dst is all zero. */
static inline veil_result veil__desc_read(const veil__desc_layouts* lay, const void* src, void* dst, veil_error* err)
{
    size_t own = lay->layout[lay->count - 1].size;
    memset(dst, 0, own);
    if (src) {
        size_t given;
        memcpy(&given, src, sizeof given);
        const veil__desc_layout* l = given == 0 ? &lay->layout[0] : NULL;
        for (int i = 0; i < lay->count && !l; ++i)
            if (given == lay->layout[i].size) l = &lay->layout[i];
        if (given > own)
            return veil_fail(err, VEIL_ERR_INVALID,
                             "%s: %s.size is %zu bytes, larger than this library's %zu: built against a newer "
                             "veil.h?",
                             lay->fn, lay->type, given, own);
        if (!l)
            return veil_fail(err, VEIL_ERR_INVALID,
                             "%s: %s.size is %zu bytes, the size of no layout this library knows (its own: %zu); "
                             "set it to sizeof(%s) or 0",
                             lay->fn, lay->type, given, own, lay->type);
        memcpy(dst, src, l->used);
    }
    memcpy(dst, &own, sizeof own);
    return VEIL_OK;
}

#endif
