// veil — a NanoVDB file's claims, checked before NanoVDB acts on them
// (C++, internal; included by io/vdb.cpp only). NanoVDB's reader takes
// sizes from the file and allocates them (a grid's size, its name's,
// each compressed chunk's), and a grid is a buffer of nodes that point at
// each other by byte offsets, which NanoVDB and its converter to OpenVDB
// follow as given: a corrupt file made them allocate what it claimed and
// read outside the buffer. file_ok() walks the file before it is read;
// grid_ok() walks a grid's nodes before it is converted.
#ifndef VEIL_NANOVDB_CHECK_HPP
#define VEIL_NANOVDB_CHECK_HPP

#include <nanovdb/NanoVDB.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace veil_nano {

[[noreturn]] inline void bad(const std::string& what, uint64_t at)
{
    throw std::string("truncated or corrupt NanoVDB file: " + what + " (at byte " + std::to_string(at) + ")");
}

// The file: segments of a 16-byte header (uint64 magic, uint32 version,
// uint16 grid count, uint16 codec 0 none, 1 zip, 2 blosc), the grids'
// 176-byte descriptions, each followed by its name (nameSize bytes, NUL
// inside: NanoVDB copies it as a C string), then each grid's bytes: its
// gridSize raw, or (zip) an int64 size and that many bytes, or (blosc)
// per 2^30 bytes of the grid an int64 size and a blosc chunk. A grid must
// fit in the file and hold at least its grid and tree headers; compressed,
// its size may be at most 1100 times its compressed bytes (deflate's limit
// is 1032; blosc's a few hundred) and a blosc chunk must claim its part.
inline void file_ok(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    in.seekg(0, std::ios::end);
    const uint64_t size = (uint64_t)std::max<std::streamoff>(0, (std::streamoff)in.tellg());
    in.seekg(0);
    uint64_t at = 0;
    auto read = [&](void* p, uint64_t n, const char* what) {
        if (n > size - at || !in.read(static_cast<char*>(p), (std::streamsize)n)) bad(what, at);
        at += n;
    };
    auto skip = [&](uint64_t n, const char* what) {
        if (n > size - at) bad(what, at);
        at += n;
        in.seekg((std::streamoff)at);
    };
    const uint64_t min_grid = sizeof(nanovdb::GridData) + sizeof(nanovdb::TreeData<3>);
    while (at < size) {
        unsigned char h[16];
        read(h, 16, "a segment header");
        uint64_t magic;
        uint16_t count, codec;
        std::memcpy(&magic, h, 8);
        std::memcpy(&count, h + 12, 2);
        std::memcpy(&codec, h + 14, 2);
        if (magic != NANOVDB_MAGIC_NUMBER) bad("not a NanoVDB segment", at - 16);
        if (codec > 2) bad("codec " + std::to_string(codec) + " (0, 1 or 2)", at - 2);
        if ((uint64_t)count * 177 > size - at) bad(std::to_string(count) + " grids", at - 4);
        std::vector<uint64_t> grid_size(count);
        for (uint16_t g = 0; g < count; ++g) {
            unsigned char m[176];
            read(m, 176, "a grid's description");
            uint32_t name;
            std::memcpy(&grid_size[g], m, 8);
            std::memcpy(&name, m + 136, 4); // after 4 uint64, 2 uint32, 2 x 3 double, 2 x 3 int32, 3 double
            if (grid_size[g] < min_grid) bad("a grid of " + std::to_string(grid_size[g]) + " bytes", at - 176);
            if (name == 0 || name > size - at) bad("a grid name of " + std::to_string(name) + " bytes", at);
            std::string bytes(name, '\0');
            read(&bytes[0], name, "a grid name");
            if (bytes.find('\0') == std::string::npos) bad("a grid name without its end", at - name);
        }
        for (uint16_t g = 0; g < count; ++g) {
            if (codec == 0) {
                skip(grid_size[g], "a grid's bytes");
                continue;
            }
            uint64_t left = grid_size[g], packed = 0;
            do {
                const uint64_t part = codec == 2 && left > (1ull << 30) ? 1ull << 30 : left;
                int64_t n;
                read(&n, 8, "a compressed chunk's size");
                if (n <= 0 || (uint64_t)n > size - at) bad("a compressed chunk of " + std::to_string(n) + " bytes", at);
                if (codec == 2) { // blosc: uint32 uncompressed size at +4, compressed at +12
                    unsigned char b[16];
                    if (n < 16) bad("a blosc chunk of " + std::to_string(n) + " bytes", at);
                    read(b, 16, "a blosc header");
                    uint32_t raw, cbytes;
                    std::memcpy(&raw, b + 4, 4);
                    std::memcpy(&cbytes, b + 12, 4);
                    if (raw != part || cbytes != (uint64_t)n)
                        bad("a blosc chunk claiming " + std::to_string(raw) + " bytes where the grid's part is " +
                                std::to_string(part), at - 16);
                    skip((uint64_t)n - 16, "a blosc chunk");
                } else {
                    skip((uint64_t)n, "a zip chunk");
                }
                packed += (uint64_t)n;
                left -= codec == 2 ? part : left;
            } while (left > 0);
            if (grid_size[g] / 1100 > packed)
                bad("a grid of " + std::to_string(grid_size[g]) + " bytes compressed into " + std::to_string(packed),
                    at);
        }
    }
}

// A grid's nodes, before the grid is used: its header (magic, size = the
// buffer's, index 0 of at least 1), the tree's root inside the buffer with
// its tiles, and every child offset (root tile -> upper node -> lower node
// -> leaf) landing 32-byte aligned after the root's tiles with the whole
// node inside the buffer (an FpN leaf's size from its own bit width, 1 to
// 16). A node reached twice is allowed (NanoVDB does not forbid it) but
// the visits are capped at one per 32 bytes of the grid: shared nodes
// could otherwise make the walk, and the conversion, exponential.
template <typename BuildT>
void grid_ok(const nanovdb::NanoGrid<BuildT>& grid, uint64_t size)
{
    using Grid = nanovdb::NanoGrid<BuildT>;
    using Root = typename Grid::TreeType::RootType;
    using Upper = typename Root::ChildNodeType;
    using Lower = typename Upper::ChildNodeType;
    using Leaf = typename Lower::ChildNodeType;
    const uint8_t* base = reinterpret_cast<const uint8_t*>(&grid);
    const nanovdb::GridData* gd = reinterpret_cast<const nanovdb::GridData*>(base);
    if (gd->mMagic != NANOVDB_MAGIC_NUMBER) bad("a grid without NanoVDB's magic number", 0);
    if (gd->mGridSize != size) bad("a grid whose size (" + std::to_string(gd->mGridSize) + ") is not its buffer's", 0);
    if (gd->mGridIndex != 0 || gd->mGridCount < 1) bad("a grid index or count out of range", 0);
    const uint64_t tree_at = sizeof(nanovdb::GridData);
    const uint64_t root_off = reinterpret_cast<const nanovdb::TreeData<3>*>(base + tree_at)->mNodeOffset[3];
    if (root_off < sizeof(nanovdb::TreeData<3>) || root_off > size - tree_at || (tree_at + root_off) % 32 ||
        sizeof(Root) > size - tree_at - root_off)
        bad("the root node outside the grid", tree_at);
    const uint64_t root_at = tree_at + root_off;
    const auto* root = reinterpret_cast<const typename Root::DataType*>(base + root_at);
    const uint64_t tiles = (uint64_t)root->mTableSize * sizeof(typename Root::DataType::Tile);
    if (tiles > size - root_at - sizeof(Root)) bad("the root's tiles outside the grid", root_at);
    const uint64_t first = root_at + sizeof(Root) + tiles; // no node before this
    uint64_t visits = 0;
    // the position of a child at `offset` bytes from a node at `at`, of at least `bytes` bytes
    auto child = [&](uint64_t at, int64_t offset, uint64_t bytes) {
        const uint64_t pos = at + (uint64_t)offset; // wraps for a negative offset below 0: caught below
        if ((offset < 0 && (uint64_t)(-(offset + 1)) + 1 > at) || pos < first || pos % 32 || bytes > size ||
            pos > size - bytes)
            bad("a child node outside the grid", at);
        if (++visits > size / 32) bad("more node visits than the grid has room for nodes", at);
        return pos;
    };
    for (uint32_t t = 0; t < root->mTableSize; ++t) {
        const int64_t c = root->tile(t)->child;
        if (!c) continue;
        const uint64_t u = child(root_at, c, sizeof(Upper));
        const auto* up = reinterpret_cast<const typename Upper::DataType*>(base + u);
        for (auto i = up->mChildMask.beginOn(); i; ++i) {
            const uint64_t l = child(u, up->mTable[*i].child, sizeof(Lower));
            const auto* lo = reinterpret_cast<const typename Lower::DataType*>(base + l);
            for (auto j = lo->mChildMask.beginOn(); j; ++j) {
                const uint64_t f = child(l, lo->mTable[*j].child, sizeof(Leaf));
                if constexpr (!Leaf::DataType::FIXED_SIZE) { // FpN: 2^(flags >> 5) bits a value, 1 to 16
                    const auto* leaf = reinterpret_cast<const typename Leaf::DataType*>(base + f);
                    if ((leaf->mFlags >> 5) > 4 || leaf->memUsage() > size - f) bad("an FpN leaf outside the grid", f);
                }
            }
        }
    }
}

} // namespace veil_nano

#endif
