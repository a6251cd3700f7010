/* veil — FNV-1a (64 bit) over bytes: the content keys of cached stages.
 * Not cryptographic; a key only has to change when its content does. */
#ifndef VEIL_HASH_H
#define VEIL_HASH_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define VEIL_FNV_OFFSET 0xcbf29ce484222325ull
#define VEIL_FNV_PRIME 0x100000001b3ull

static inline uint64_t veil_hash_bytes(uint64_t h, const void* data, size_t n)
{
    const unsigned char* p = (const unsigned char*)data;
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * VEIL_FNV_PRIME;
    return h;
}

/* The same walk over 8-byte words (memcpy'd: any alignment), with a
 * rotation so that a word's high bits reach the low bits of later steps:
 * for large arrays (a grid given from memory), ~8x fewer steps. Not equal
 * to veil_hash_bytes of the same bytes. */
static inline uint64_t veil_hash_words(uint64_t h, const void* data, size_t n)
{
    const unsigned char* p = (const unsigned char*)data;
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t w;
        memcpy(&w, p + i, 8);
        h = ((h ^ w) * VEIL_FNV_PRIME);
        h ^= h >> 29;
    }
    return veil_hash_bytes(h, p + i, n - i);
}

#endif
