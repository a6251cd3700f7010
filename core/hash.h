/* veil — FNV-1a (64 bit) over bytes: the content keys of cached stages.
 * Not cryptographic; a key only has to change when its content does. */
#ifndef VEIL_HASH_H
#define VEIL_HASH_H

#include <stddef.h>
#include <stdint.h>

#define VEIL_FNV_OFFSET 0xcbf29ce484222325ull
#define VEIL_FNV_PRIME 0x100000001b3ull

static inline uint64_t veil_hash_bytes(uint64_t h, const void* data, size_t n)
{
    const unsigned char* p = (const unsigned char*)data;
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * VEIL_FNV_PRIME;
    return h;
}

#endif
