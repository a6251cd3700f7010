// veil tests — writes the sparse grids that a hostile user would hand to
// `veil render` (issue 22, items 3, 4 and 9): small files whose active
// values stand for far more work than their size says. Made at test time,
// like make_test_vdbs's files; the tests say what each must do.
//
//   make_sparse_vdbs tile FILE LEVEL       one active tile of value 1 at the
//                                          origin: LEVEL 1, 2 or 3 (8^3, 128^3
//                                          or 4096^3 voxels in OpenVDB's
//                                          default tree), voxel 0.01 m
//   make_sparse_vdbs scatter FILE LEAVES PER SIDE
//                                          LEAVES leaves at places hashed over
//                                          a SIDE^3 index box, PER voxels
//                                          each at places hashed in the leaf
//                                          (value 1), voxel 0.01 m
//   make_sparse_vdbs wide FILE SIDE        two voxels of value 1, at index
//                                          (0, 0, 0) and (SIDE - 1, 0, 0),
//                                          voxel 0.01 m
//
// Files are deterministic (the scatter's places come from a fixed hash).
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>

using openvdb::Coord;
using openvdb::FloatGrid;

namespace {

constexpr double VOXEL = 0.01; // m: the grids

FloatGrid::Ptr density()
{
    FloatGrid::Ptr g = FloatGrid::create(0.0f);
    g->setName("density");
    g->setGridClass(openvdb::GRID_FOG_VOLUME);
    g->setTransform(openvdb::math::Transform::createLinearTransform(VOXEL));
    return g;
}

// A 32-bit mix of (i, seed): multiply-xorshift rounds.
uint32_t mix(uint32_t i, uint32_t seed)
{
    uint32_t h = i * 0x9e3779b9u ^ seed * 0x85ebca6bu;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

void write(const char* file, FloatGrid::Ptr g)
{
    openvdb::io::File f(file);
    f.write({g});
    f.close();
}

long arg(const char* s, long lo, long hi)
{
    char* end = nullptr;
    long v = std::strtol(s, &end, 10);
    if (!*s || *end || v < lo || v > hi) throw std::runtime_error(std::string("bad number: ") + s);
    return v;
}

} // namespace

int main(int argc, char** argv)
{
    try {
        openvdb::initialize();
        if (argc == 4 && !std::strcmp(argv[1], "tile")) {
            const long level = arg(argv[3], 1, 3);
            FloatGrid::Ptr g = density();
            g->tree().addTile((openvdb::Index)level, Coord(0, 0, 0), 1.0f, true);
            if (g->tree().activeTileCount() != 1) throw std::runtime_error("the tile was not made");
            write(argv[2], g);
        } else if (argc == 6 && !std::strcmp(argv[1], "scatter")) {
            const long leaves = arg(argv[3], 1, 1000000), per = arg(argv[4], 1, 512), side = arg(argv[5], 8, 1 << 20);
            FloatGrid::Ptr g = density();
            FloatGrid::Accessor acc = g->getAccessor();
            const uint32_t cells = (uint32_t)(side / 8); // leaf places a side
            for (long i = 0; i < leaves; ++i) {
                Coord leaf(8 * (int)(mix((uint32_t)i, 1) % cells), 8 * (int)(mix((uint32_t)i, 2) % cells),
                           8 * (int)(mix((uint32_t)i, 3) % cells));
                for (long k = 0; k < per; ++k) { // `per` voxels at places hashed in the leaf (a few may coincide)
                    const uint32_t h = mix((uint32_t)(i * 512 + k), 4);
                    acc.setValue(leaf + Coord((int)(h & 7), (int)(h >> 3 & 7), (int)(h >> 6 & 7)), 1.0f);
                }
            }
            write(argv[2], g);
        } else if (argc == 4 && !std::strcmp(argv[1], "wide")) {
            const long side = arg(argv[3], 2, 1 << 24);
            FloatGrid::Ptr g = density();
            g->tree().setValue(Coord(0, 0, 0), 1.0f);
            g->tree().setValue(Coord((int)side - 1, 0, 0), 1.0f);
            write(argv[2], g);
        } else {
            std::fprintf(stderr, "usage: %s tile FILE LEVEL | scatter FILE LEAVES PER SIDE | wide FILE SIDE\n", argv[0]);
            return 2;
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "make_sparse_vdbs: %s\n", e.what());
        return 1;
    }
    return 0;
}
