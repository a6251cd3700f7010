// veil tests — writes the OpenVDB files that the VDB tests read (the
// vdb_data fixture of tests/io/, tests/volume/, tests/render/, tests/scene/
// and tests/cli/), so that no binary test data is committed.
//
//   make_test_vdbs DIR           the test files (below), deterministic
//   make_test_vdbs DIR --big     also big_plume.vdb (~10^6 active voxels, for timing)
//   make_test_vdbs --plume FILE  only the plume, at the size of big_plume.vdb, into FILE
//   make_test_vdbs --plume-faded FILE  the same, faded out at its bottom and top (bench/peers.py)
//   make_test_vdbs --pyro FILE   the base-size plume with a "temperature" grid (0..1), into FILE
//   make_test_vdbs --smoke-vel FILE  a 128^3 plume with a swirling "vel" (motion blur's timing:
//                                docs/performance.md)
//   make_test_vdbs --pair A B    two overlapping plumes for a two-source scene (bench/vdb_import.py):
//                                A the base plume (voxel 0.02 m), B a smaller one (voxel 0.03 m,
//                                moved by (0.35, 0.5, 0.1) m: off A's lattice)
//                                (the example scene data/scenes/vdb_smoke.json: `make data`)
//
// Files (grid name, what it is for):
//   fog_sphere.vdb       "density": createLevelSetSphere + sdfToFogVolume
//   level_set.vdb        "surface": a narrow-band level set sphere (refused unless converted)
//   vec3.vdb             "velocity": a Vec3f grid (refused, naming its type)
//   empty.vdb            "density": a float grid with no active voxel
//   offset_scaled.vdb    "density": voxel 0.25 m, translated by (1, -2, 3); the linear field
//                        1 + i/2 + j/4 + k/8 on the index block [0, 15]^3 (pins the convention)
//   offset_scaled.nvdb   the same grid written by NanoVDB (io/vdb.cpp reads .nvdb too)
//   offset_scaled_half.vdb the same grid stored as half floats (values exact in half)
//   emissive_slab.vdb    "density" and "heat" 1 on [0,19]x[0,19]x[0,9], voxel 0.1 m
//   rotated.vdb          "density": a Gaussian blob under scale + rotation + translation
//   frustum.vdb          "density": a frustum (non-affine) transform
//   far_apart.vdb        "density": two voxels at index (0,0,0) and (1100,1100,1100)
//   sparse_puffs.vdb     "density", voxel 0.05 m: Gaussian puffs over a 4096^3 index box
//                        (under 1e-5 of it active): the crop's three and 24 more (below)
//   sparse_crop.vdb      "density": the crop's three puffs alone (fits a dense grid)
//   two_grids.vdb        "temperature" then "density" (written without stats metadata)
//   smoke_plume.vdb      "density": a procedural noisy plume, ~10^5 active voxels, hard edges
//   truncated.vdb        the first half of fog_sphere.vdb's bytes
//   garbage.vdb          bytes that are not an OpenVDB file
//   types_blosc.vdb, types_zip.vdb, types_raw.vdb, types_half.vdb (tree_files below):
//                        a grid of each value type OpenVDB registers for voxels, a level
//                        set and an instance, under each compression, without stats
//                        metadata (so reading the file's statistics reads every tree)
//   chunk_big.vdb, chunk_raw.vdb, chunk_header.vdb, root_count.vdb, no_offsets.vdb,
//   half_mismatch.vdb, nano_size.nvdb, nano_child.nvdb: one small grid each,
//                        with one claim of its tree made absurd (tree_files below)
//   values.vdb           grids whose values the pipeline cannot carry (value_files below)
//   blur.vdb, moving.0001.vdb .. moving.0003.vdb: motion blur's (blur_files below)
//   values_nan.nvdb      its "density_nan" grid written by NanoVDB
//
// The values that tests/io/test_vdb.c recomputes (the linear field, the two
// grids' voxel counts) are stated in the comments next to them.
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

using openvdb::Coord;
using openvdb::FloatGrid;

namespace {

std::string g_dir;

std::string path(const char* name) { return g_dir + "/" + name; }

void write(const char* name, openvdb::GridPtrVec grids, bool stats = true)
{
    openvdb::io::File file(path(name));
    file.setGridStatsMetadataEnabled(stats);
    file.write(grids);
    file.close();
}

FloatGrid::Ptr float_grid(const char* name, double voxel)
{
    FloatGrid::Ptr g = FloatGrid::create(0.0f);
    g->setName(name);
    g->setGridClass(openvdb::GRID_FOG_VOLUME);
    g->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    return g;
}

// Deterministic lattice hash in [0, 1): an integer mix of the three
// coordinates and a seed (multiply-xorshift rounds).
double hash01(int x, int y, int z, uint32_t seed)
{
    uint32_t h = seed ^ (uint32_t)x * 0x8da6b343u ^ (uint32_t)y * 0xd8163841u ^ (uint32_t)z * 0xcb1ab31fu;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return (double)h / 4294967296.0;
}

// Value noise: the lattice hash, trilinearly blended with a smoothstep weight.
double value_noise(double x, double y, double z, uint32_t seed)
{
    int x0 = (int)std::floor(x), y0 = (int)std::floor(y), z0 = (int)std::floor(z);
    double fx = x - x0, fy = y - y0, fz = z - z0;
    fx = fx * fx * (3 - 2 * fx);
    fy = fy * fy * (3 - 2 * fy);
    fz = fz * fz * (3 - 2 * fz);
    double v = 0.0;
    for (int c = 0; c < 8; ++c) {
        int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
        double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
        v += w * hash01(x0 + dx, y0 + dy, z0 + dz, seed);
    }
    return v;
}

// A rising plume in index space, `s` times the base size (height 100 s
// voxels, radius 10 s at the bottom to 25 s at the top, drifting in x),
// whose density is a radial fall-off times three octaves of value noise;
// voxels below 0.05 are left inactive (a hard edge, as smoke caches have).
// `faded`: the density also fades to nothing over the lowest and highest
// tenth of the height, so no face of the bounding box cuts through dense
// smoke (bench/peers.py: OpenVDB's samplers ramp a cut face's density to
// the background over one more voxel, veil's medium ends at the last
// voxel centre: docs/peers.md).
FloatGrid::Ptr plume(double s, bool faded = false)
{
    FloatGrid::Ptr g = float_grid("density", 0.02);
    FloatGrid::Accessor acc = g->getAccessor();
    const int height = (int)std::lround(100 * s);
    const double cutoff = 0.05;
    for (int y = 0; y < height; ++y) {
        double t = (double)y / height;
        double r = s * (10.0 + 15.0 * t), cx = 4.0 * s * std::sin(6.0 * t);
        int ri = (int)std::ceil(r);
        for (int z = -ri; z <= ri; ++z)
            for (int x = (int)std::floor(cx) - ri; x <= (int)std::ceil(cx) + ri; ++x) {
                double d = std::sqrt((x - cx) * (x - cx) + (double)z * z) / r;
                if (d >= 1.0) continue;
                double n = 0.0, amp = 0.5, f = 1.0 / (6.0 * s);
                for (int o = 0; o < 3; ++o, amp *= 0.5, f *= 2.0)
                    n += amp * value_noise(x * f, y * f, z * f, 17u + (uint32_t)o);
                double v = (1.0 - d * d) * (0.3 + 1.4 * n) * (1.0 - 0.5 * t);
                if (faded) {
                    double u = std::min(1.0, std::min(t, 1.0 - t) / 0.1);
                    v *= u * u * (3 - 2 * u);
                }
                if (v > cutoff) acc.setValue(Coord(x, y, z), (float)v);
            }
    }
    return g;
}

// The plume's temperature for a pyro test: on the plume's voxels, hottest at
// the base and the axis, value (1 - t)(1 - d^2) in [0, 1] (a scene maps it
// to kelvin with "scale" and "offset").
FloatGrid::Ptr plume_temperature(const FloatGrid& density)
{
    FloatGrid::Ptr g = float_grid("temperature", 0.02);
    FloatGrid::Accessor acc = g->getAccessor();
    openvdb::CoordBBox box = density.evalActiveVoxelBoundingBox();
    const double height = box.max().y() + 1.0;
    for (FloatGrid::ValueOnCIter it = density.cbeginValueOn(); it; ++it) {
        const Coord c = it.getCoord();
        double t = c.y() / height, r = 10.0 + 15.0 * t, cx = 4.0 * std::sin(6.0 * t) * (r / (10.0 + 15.0 * t));
        double d = std::sqrt((c.x() - cx) * (c.x() - cx) + (double)c.z() * c.z()) / r;
        double v = (1.0 - t) * (1.0 - std::min(d * d, 1.0));
        if (v > 0.0) acc.setValue(c, (float)v);
    }
    return g;
}

void copy_prefix(const char* from, const char* to, double fraction)
{
    std::ifstream in(path(from), std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream out(path(to), std::ios::binary);
    out.write(bytes.data(), (std::streamsize)(bytes.size() * fraction));
    if (!out) throw std::runtime_error(std::string("cannot write ") + path(to));
}

// Adds a Gaussian puff (peak a, sigma s voxels, cut at 3 s) centred on index c.
void puff(FloatGrid& g, Coord c, float a, double s)
{
    FloatGrid::Accessor acc = g.getAccessor();
    int r = (int)std::ceil(3.0 * s);
    for (int k = -r; k <= r; ++k)
        for (int j = -r; j <= r; ++j)
            for (int i = -r; i <= r; ++i) {
                double r2 = (double)i * i + (double)j * j + (double)k * k;
                if (r2 > 9.0 * s * s) continue;
                Coord p = c + Coord(i, j, k);
                acc.setValue(p, acc.getValue(p) + a * (float)std::exp(-0.5 * r2 / (s * s)));
            }
}

// The sparse pair (tests/volume/test_sparse.c). The crop: three puffs (sigma 3
// voxels) around index (2000, 2000, 9), their lowest voxel at k = 0. The
// rest: puffs reaching the far corners (4095, 4095, 4095) and (0, 0, 4095), and 23 more at
// pseudo-random places with j <= 1500 and k >= 40: from a camera on -z
// looking at the crop with a narrow view they are out of sight, and under
// a sun straight down (-y) they shade nothing of the crop. Both files' boxes
// then begin on the same k plane, the crop's.
void sparse_pair()
{
    const Coord crop[3] = {Coord(2000, 2000, 9), Coord(2010, 2004, 11), Coord(1993, 2008, 12)};
    FloatGrid::Ptr all = float_grid("density", 0.05), part = float_grid("density", 0.05);
    for (const Coord& c : crop) puff(*all, c, 1.0f, 3.0), puff(*part, c, 1.0f, 3.0);
    puff(*all, Coord(4095 - 9, 4095 - 9, 4095 - 9), 1.0f, 3.0);
    puff(*all, Coord(9, 9, 4095 - 9), 1.0f, 3.0);
    uint64_t x = 12345;
    for (int n = 0; n < 23; ++n) {
        int v[3];
        for (int a = 0; a < 3; ++a) {
            x = x * 6364136223846793005ull + 1442695040888963407ull;
            v[a] = 20 + (int)((x >> 33) % 4056);
        }
        puff(*all, Coord(v[0], 20 + v[1] % 1480, 40 + v[2] % 4000), 0.8f, 3.0);
    }
    write("sparse_puffs.vdb", {all});
    write("sparse_crop.vdb", {part});
}

void tree_files(); // below: the tree files

// A grid of the 8^3 index box [0, 7]^3, voxel 0.1 m, every voxel `fill`
// but voxel (3, 3, 3), which is `odd`.
FloatGrid::Ptr box_grid(const char* name, float fill, float odd)
{
    FloatGrid::Ptr g = float_grid(name, 0.1);
    FloatGrid::Accessor acc = g->getAccessor();
    for (int k = 0; k < 8; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i) acc.setValue(Coord(i, j, k), i == 3 && j == 3 && k == 3 ? odd : fill);
    return g;
}

// values.vdb: the grids of issue 22 (items 5 and 6) that the float
// pipeline cannot carry, each beside good ones, all on the 8^3 box of
// box_grid (tests/volume/test_grid_values.c, tests/cli/values_cli.sh):
// "density" 1; "density_nan", "density_neg_inf", "density_big" (3e38) one
// such voxel; "density_negative" -0.5 on the 64 voxels of i = 0;
// "density_tile_nan" 1 and an active 8^3 tile of NaN beside it (512
// voxels); "heat" 1, "heat_inf" and "heat_big" one +inf or 3e38 voxel,
// "heat_negative" -1 everywhere; "temperature" 1500 (K), "temperature_big"
// one 3e38 voxel, "temperature_inf" one +inf voxel.
void value_files()
{
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    FloatGrid::Ptr negative = box_grid("density_negative", 1.0f, 1.0f);
    for (int k = 0; k < 8; ++k)
        for (int j = 0; j < 8; ++j) negative->tree().setValue(Coord(0, j, k), -0.5f);
    FloatGrid::Ptr tile = box_grid("density_tile_nan", 1.0f, 1.0f);
    tile->tree().addTile(1, Coord(8, 0, 0), nan, true);
    FloatGrid::Ptr density_nan = box_grid("density_nan", 1.0f, nan);
    write("values.vdb", {box_grid("density", 1.0f, 1.0f), density_nan, box_grid("density_neg_inf", 1.0f, -inf),
                         box_grid("density_big", 1.0f, 3e38f), negative, tile, box_grid("heat", 1.0f, 1.0f),
                         box_grid("heat_inf", 1.0f, inf), box_grid("heat_big", 1.0f, 3e38f),
                         box_grid("heat_negative", -1.0f, -1.0f), box_grid("temperature", 1500.0f, 1500.0f),
                         box_grid("temperature_big", 1500.0f, 3e38f), box_grid("temperature_inf", 1500.0f, inf)});
    nanovdb::io::writeGrid(path("values_nan.nvdb"), nanovdb::openToNanoVDB(*density_nan));
}

// Motion blur's files (tests/volume/test_motion_blur.c, tests/render/test_motion_blur.c,
// tests/cli/turntable_motion_blur.sh), voxel 0.125 m (exact in binary, so that the tests'
// shifts are whole voxels exactly):
//   blur.vdb: "density" a Gaussian puff (peak 1, sigma 3 voxels, cut at 3 sigma) at index
//     (0, 0, 0); "anchor" two active voxels of value 0 at index (-16, -16, -16) and (16, 16,
//     16) (a second source that fixes the volume's box whatever the puff's shift); "vel" the
//     constant vector (1, 0, 0) (m per unit of time) on the active box [-40, 40]^3, "vel_d"
//     the same as vec3d, "vel_zero" (0, 0, 0) there, "wind.x", "wind.y", "wind.z" the same
//     field as three float grids (1, 0, 0); "speed" a float grid (not a vector); "swirl" a
//     rotation about the z axis through world (-1, 0, 0) at 1 rad per unit of time, v = (-y,
//     x + 1, 0) at world (x, y, z), on [-40, 40]^3 (linear, so its trilinear field is exact)
//   moving.000F.vdb (F = 1, 2, 3): "density" the puff at index (4 (F - 2), 0, 0), "vel"
//     (12, 0, 0) m/s on [-40, 40]^3: at 24 fps the puff's own motion, 4 voxels a frame
FloatGrid::Ptr blur_puff(int x)
{
    FloatGrid::Ptr g = float_grid("density", 0.125);
    puff(*g, Coord(x, 0, 0), 1.0f, 3.0);
    return g;
}

void blur_files()
{
    const openvdb::CoordBBox box(Coord(-40), Coord(40));
    auto vec = [&](const char* name, float x) {
        openvdb::Vec3SGrid::Ptr v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        v->setName(name);
        v->setTransform(openvdb::math::Transform::createLinearTransform(0.125));
        v->tree().fill(box, openvdb::Vec3s(x, 0.0f, 0.0f), true);
        return v;
    };
    openvdb::Vec3DGrid::Ptr vd = openvdb::Vec3DGrid::create(openvdb::Vec3d(0.0));
    vd->setName("vel_d");
    vd->setTransform(openvdb::math::Transform::createLinearTransform(0.125));
    vd->tree().fill(box, openvdb::Vec3d(1.0, 0.0, 0.0), true);
    FloatGrid::Ptr anchor = float_grid("anchor", 0.125), speed = float_grid("speed", 0.125);
    anchor->tree().setValueOn(Coord(-16), 0.0f);
    anchor->tree().setValueOn(Coord(16), 0.0f);
    speed->tree().setValue(Coord(0), 1.0f);
    openvdb::Vec3SGrid::Ptr swirl = vec("swirl", 0.0f);
    for (auto p = box.begin(); p; ++p)
        swirl->tree().setValue(*p, openvdb::Vec3s(-0.125f * (float)(*p).y(), 0.125f * (float)(*p).x() + 1.0f, 0.0f));
    openvdb::GridPtrVec grids = {blur_puff(0), anchor, vec("vel", 1.0f), vd, vec("vel_zero", 0.0f), speed, swirl};
    for (int a = 0; a < 3; ++a) {
        FloatGrid::Ptr w = float_grid((std::string("wind.") + "xyz"[a]).c_str(), 0.125);
        w->tree().fill(box, a == 0 ? 1.0f : 0.0f, true);
        grids.push_back(w);
    }
    write("blur.vdb", grids);
    for (int f = 1; f <= 3; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "moving.%04d.vdb", f);
        write(name, {blur_puff(4 * (f - 2)), vec("vel", 12.0f)});
    }
}

// A smoke-like grid with velocity for motion blur's timing: the plume at 1.28 times
// the base size (128 voxels tall, voxel 0.02 m) and "vel" on its active voxels
// dilated by 8, a swirl about the plume's axis plus an updraft (m/s): (-w z, u, w x)
// with w = 6 rad/s and u = 1.5 m/s, up to about 3 m/s at the rim.
openvdb::GridPtrVec smoke_with_velocity()
{
    FloatGrid::Ptr d = plume(1.28);
    openvdb::Vec3SGrid::Ptr v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    v->setName("vel");
    v->setTransform(d->transform().copy());
    openvdb::CoordBBox box = d->evalActiveVoxelBoundingBox();
    box.expand(8);
    const double w = 6.0, u = 1.5, h = 0.02;
    openvdb::Vec3SGrid::Accessor acc = v->getAccessor();
    for (auto p = box.begin(); p; ++p) {
        const double x = (*p).x() * h, z = (*p).z() * h;
        acc.setValue(*p, openvdb::Vec3s((float)(-w * z), (float)u, (float)(w * x)));
    }
    return {d, v};
}

void make_all(bool big)
{
    const float sphere_voxel = 0.05f, sphere_radius = 1.0f; // 20 voxels
    FloatGrid::Ptr ls = openvdb::tools::createLevelSetSphere<FloatGrid>(sphere_radius, openvdb::Vec3f(0.1f, -0.2f, 0.3f),
                                                                         sphere_voxel);
    ls->setName("surface");
    write("level_set.vdb", {ls});

    FloatGrid::Ptr fog = ls->deepCopy();
    openvdb::tools::sdfToFogVolume(*fog);
    fog->setName("density");
    write("fog_sphere.vdb", {fog});
    copy_prefix("fog_sphere.vdb", "truncated.vdb", 0.5);

    openvdb::Vec3SGrid::Ptr vel = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    vel->setName("velocity");
    for (int i = 0; i < 8; ++i) vel->tree().setValue(Coord(i, 0, 0), openvdb::Vec3s(1.0f, 0.0f, (float)i));
    write("vec3.vdb", {vel});

    write("empty.vdb", {float_grid("density", 0.1)});

    // The linear field 1 + i/2 + j/4 + k/8 on [0, 15]^3, voxel 0.25 m,
    // index (0,0,0) at world (1, -2, 3): voxel (i,j,k)'s centre is at
    // (1 + i/4, -2 + j/4, 3 + k/4).
    FloatGrid::Ptr lin = float_grid("density", 0.25);
    lin->transform().postTranslate(openvdb::Vec3d(1.0, -2.0, 3.0));
    {
        FloatGrid::Accessor acc = lin->getAccessor();
        for (int k = 0; k < 16; ++k)
            for (int j = 0; j < 16; ++j)
                for (int i = 0; i < 16; ++i) acc.setValue(Coord(i, j, k), 1.0f + i / 2.0f + j / 4.0f + k / 8.0f);
    }
    write("offset_scaled.vdb", {lin});

    // An emissive slab: "density" and "heat" both 1 on the index box
    // [0, 19] x [0, 19] x [0, 9], voxel 0.1 m (tests/render/test_emission.c)
    FloatGrid::Ptr slab = float_grid("density", 0.1), heat = float_grid("heat", 0.1);
    {
        FloatGrid::Accessor a = slab->getAccessor(), b = heat->getAccessor();
        for (int k = 0; k < 10; ++k)
            for (int j = 0; j < 20; ++j)
                for (int i = 0; i < 20; ++i) a.setValue(Coord(i, j, k), 1.0f), b.setValue(Coord(i, j, k), 1.0f);
    }
    write("emissive_slab.vdb", {slab, heat});
    // the same grid stored as half floats (as production files often are): its values (multiples
    // of 1/8 below 16) are exact in half, so a reader must return them bit for bit
    {
        FloatGrid::Ptr half = lin->deepCopy();
        half->setSaveFloatAsHalf(true);
        write("offset_scaled_half.vdb", {half});
    }
    // the same grid as NanoVDB (pbrt-v4's scenes ship .nvdb): readers must see the same values
    nanovdb::io::writeGrid(path("offset_scaled.nvdb"), nanovdb::openToNanoVDB(*lin));

    // A Gaussian blob (sigma 5 voxels, cut at 4 sigma) under voxel 0.05 m,
    // rotated 30 deg about z then 20 deg about x, then moved to (0.5, 0.25, -1).
    FloatGrid::Ptr rot = float_grid("density", 0.05);
    rot->transform().postRotate(30.0 * M_PI / 180.0, openvdb::math::Z_AXIS);
    rot->transform().postRotate(20.0 * M_PI / 180.0, openvdb::math::X_AXIS);
    rot->transform().postTranslate(openvdb::Vec3d(0.5, 0.25, -1.0));
    {
        FloatGrid::Accessor acc = rot->getAccessor();
        const double sigma = 5.0;
        for (int k = -20; k <= 20; ++k)
            for (int j = -20; j <= 20; ++j)
                for (int i = -20; i <= 20; ++i) {
                    double r2 = (double)i * i + (double)j * j + (double)k * k;
                    if (r2 <= 16.0 * sigma * sigma) acc.setValue(Coord(i, j, k), (float)std::exp(-0.5 * r2 / (sigma * sigma)));
                }
    }
    write("rotated.vdb", {rot});

    FloatGrid::Ptr fr = float_grid("density", 1.0);
    fr->setTransform(openvdb::math::Transform::createFrustumTransform(
        openvdb::BBoxd(openvdb::Vec3d(0.0), openvdb::Vec3d(15.0)), 0.5, 2.0, 1.0));
    fr->tree().setValue(Coord(1, 2, 3), 1.0f);
    write("frustum.vdb", {fr});

    // Two voxels 1100 apart on each axis: a dense index box of 1103^3 =
    // 1.34e9 values (with the zero ring), over VEIL_VDB_MAX_DENSE_VOXELS.
    FloatGrid::Ptr far = float_grid("density", 0.1);
    far->tree().setValue(Coord(0, 0, 0), 1.0f);
    far->tree().setValue(Coord(1100, 1100, 1100), 1.0f);
    write("far_apart.vdb", {far});

    // "temperature" first (3 active voxels), then "density" (5 active voxels).
    FloatGrid::Ptr temp = float_grid("temperature", 0.1), dens = float_grid("density", 0.1);
    for (int i = 0; i < 3; ++i) temp->tree().setValue(Coord(i, 0, 0), 300.0f);
    for (int i = 0; i < 5; ++i) dens->tree().setValue(Coord(0, i, 0), 0.5f);
    write("two_grids.vdb", {temp, dens}, false);

    sparse_pair();
    value_files();
    blur_files();

    write("smoke_plume.vdb", {plume(1.0)});
    if (big) write("big_plume.vdb", {plume(2.2)});

    tree_files();

    std::ofstream garbage(path("garbage.vdb"), std::ios::binary);
    for (int i = 0; i < 64; ++i) garbage << "this is not an OpenVDB file\n";
    if (!garbage) throw std::runtime_error("cannot write " + path("garbage.vdb"));
}

// A grid of `G` named `name`: value `a` at 37 x 15 x 10 scattered voxels
// (x -40..68 step 3, y 0..196 step 14, z 0..117 step 13: 5 550 active
// voxels in 2 100 leaves, so that OpenVDB's delayed-load metadata
// compresses its per-leaf arrays), an active tile of 8^3 = 512 voxels and
// an inactive 128^3 tile of `b` (the background); `narrow` keeps it all in
// one 4096^3 node and 54 leaves (x 0..69, y 0..28, z 0..13: 24 x 3 x 2
// voxels, and the small tile) for the uncompressed file, where each node
// and leaf stores all its values. Active voxels: 6 062, or 656 when narrow
// (tests/io/test_vdb_trees.c).
template <typename G>
typename G::Ptr typed_grid(const char* name, typename G::ValueType a, typename G::ValueType b, bool narrow)
{
    typename G::Ptr g = G::create(b);
    g->setName(name);
    typename G::Accessor acc = g->getAccessor();
    for (int i = narrow ? 0 : -40; i < 70; i += 3)
        for (int j = 0; j < (narrow ? 3 : 15); ++j)
            for (int k = 0; k < (narrow ? 2 : 10); ++k) acc.setValue(Coord(i, j * 14, k * 13), a);
    g->tree().addTile(1, Coord(256, 0, 0), a, true);
    if (!narrow) g->tree().addTile(2, Coord(8192, 0, 0), b, false);
    return g;
}

// Every grid type of tree_files(), and a level set (negative inactive
// values: the mask-compression cases that store inactive values) and an
// instance of the float grid.
openvdb::GridPtrVec typed_grids(bool narrow, bool half)
{
    using namespace openvdb;
    GridPtrVec v = {typed_grid<FloatGrid>("float", 1.5f, 0.25f, narrow),
                    typed_grid<DoubleGrid>("double", 2.5, -1.0, narrow),
                    typed_grid<Int32Grid>("int32", 7, 3, narrow),
                    typed_grid<Int64Grid>("int64", 9, 2, narrow),
                    typed_grid<Vec3SGrid>("vec3s", Vec3s(1, 2, 3), Vec3s(0.5f), narrow),
                    typed_grid<Vec3DGrid>("vec3d", Vec3d(1, 2, 3), Vec3d(-1), narrow),
                    typed_grid<Vec3IGrid>("vec3i", Vec3i(1, 2, 3), Vec3i(4), narrow),
                    typed_grid<BoolGrid>("bool", true, false, narrow)};
    FloatGrid::Ptr ls = openvdb::tools::createLevelSetSphere<FloatGrid>(10.0f, openvdb::Vec3f(0.0f), 1.0f, 3.0f);
    ls->setName("level_set");
    v.push_back(ls);
    GridBase::Ptr inst = v[0]->copyGrid(); // shares the float grid's tree: written as an instance
    inst->setName("instance");
    v.push_back(inst);
    for (auto& g : v) g->setSaveFloatAsHalf(half);
    return v;
}

std::vector<char> read_bytes(const std::string& p)
{
    std::ifstream in(p, std::ios::binary);
    return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_bytes(const std::string& p, const std::vector<char>& b)
{
    std::ofstream out(p, std::ios::binary);
    out.write(b.data(), (std::streamsize)b.size());
    if (!out) throw std::runtime_error("cannot write " + p);
}

uint32_t le32(const char* p)
{
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

// The one offset in b where match(b, offset) holds (the patterns below are
// chosen unique in their small files; not unique is an error, not a guess).
template <typename M>
size_t find_one(const std::vector<char>& b, const char* what, M match)
{
    size_t at = SIZE_MAX;
    for (size_t i = 0; i + 32 <= b.size(); ++i)
        if (match(b, i)) {
            if (at != SIZE_MAX) throw std::runtime_error(std::string("more than one ") + what);
            at = i;
        }
    if (at == SIZE_MAX) throw std::runtime_error(std::string("no ") + what);
    return at;
}

// The tree files: the typed grids under each compression (zip and blosc
// with OpenVDB's active-mask compression, as OpenVDB writes by default),
// and four files made from a one-leaf float grid (512 values i/7, blosc)
// by changing one claim of its tree, each of which OpenVDB took as given:
//   chunk_big.vdb     the leaf's blosc chunk claims 10^10 bytes (allocated
//                     before reading: 10 GB)
//   chunk_raw.vdb     a leaf of 4 active values (16 bytes, in a 32-byte blosc
//                     chunk) claims instead 4096 bytes stored raw (size
//                     -4096: read into its 16-byte buffer, a heap overflow)
//   chunk_header.vdb  the blosc header inside the chunk claims 2^30 bytes
//                     uncompressed where the leaf holds 2 048
//   root_count.vdb    the root claims 2^31 children (each a 32^3 node of
//                     256 KB, allocated as the reading goes on)
//   no_offsets.vdb    says it has no grid offsets (as io::Stream writes):
//                     io::File then reads each grid whole as it comes
//   half_mismatch.vdb a grid stored as half whose is_saved_as_half_float
//                     metadata says false: OpenVDB reads its tree as floats
//   nano_size.nvdb    a NanoVDB grid described as 2^40 bytes (allocated before reading)
//   nano_child.nvdb   a NanoVDB grid whose root points at its upper node 2^40 bytes away
void tree_files()
{
    using openvdb::io::COMPRESS_ACTIVE_MASK;
    using openvdb::io::COMPRESS_BLOSC;
    using openvdb::io::COMPRESS_NONE;
    using openvdb::io::COMPRESS_ZIP;
    const struct {
        const char* name;
        uint32_t compression;
        bool half, narrow;
    } files[] = {{"types_blosc.vdb", COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK, false, false},
                 {"types_zip.vdb", COMPRESS_ZIP | COMPRESS_ACTIVE_MASK, false, false},
                 {"types_raw.vdb", COMPRESS_NONE, false, true},
                 {"types_half.vdb", COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK, true, false}};
    for (const auto& f : files) {
        openvdb::io::File file(path(f.name));
        file.setGridStatsMetadataEnabled(false);
        file.setCompression(f.compression);
        file.write(typed_grids(f.narrow, f.half));
        file.close();
    }

    auto one_leaf = [](const char* name, int active) {
        FloatGrid::Ptr g = float_grid("density", 0.1);
        FloatGrid::Accessor acc = g->getAccessor();
        for (int n = 0; n < active; ++n) acc.setValue(Coord(n & 7, (n >> 3) & 7, n >> 6), 1.0f + (float)n / 7.0f);
        openvdb::io::File file(path(name));
        file.setCompression(COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK);
        file.write({g});
        file.close();
        return read_bytes(path(name));
    };
    // a blosc chunk of the leaf: int64 size n > 0, then blosc's header
    // (uint32 uncompressed bytes at +4, compressed bytes at +12 = n)
    auto blosc_chunk = [](const std::vector<char>& b, size_t i) {
        int64_t n;
        std::memcpy(&n, &b[i], 8);
        return n > 16 && n < 100000 && le32(&b[i + 12]) == 2048 && le32(&b[i + 20]) == (uint32_t)n;
    };
    std::vector<char> b = one_leaf("chunk_big.vdb", 512);
    size_t at = find_one(b, "blosc chunk", blosc_chunk);
    const int64_t huge = 10000000000;
    std::memcpy(&b[at], &huge, 8);
    write_bytes(path("chunk_big.vdb"), b);

    b = one_leaf("chunk_header.vdb", 512);
    at = find_one(b, "blosc chunk", blosc_chunk);
    const uint32_t claim = 1u << 30;
    std::memcpy(&b[at + 12], &claim, 4);
    write_bytes(path("chunk_header.vdb"), b);

    b = one_leaf("root_count.vdb", 512);
    // the root: int32 buffer count 1, background 0.0f, 0 tiles, 1 child
    const char root[16] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0};
    at = find_one(b, "root", [&](const std::vector<char>& v, size_t i) { return std::memcmp(&v[i], root, 16) == 0; });
    const uint32_t children = 1u << 31;
    std::memcpy(&b[at + 12], &children, 4);
    write_bytes(path("root_count.vdb"), b);

    { // the leaf stored as half, its is_saved_as_half_float bool turned false
        FloatGrid::Ptr g = float_grid("density", 0.1);
        g->tree().setValue(Coord(1, 2, 3), 0.5f);
        g->setSaveFloatAsHalf(true);
        write("half_mismatch.vdb", {g});
        b = read_bytes(path("half_mismatch.vdb"));
        const std::string key = "is_saved_as_half_float";
        at = find_one(b, "half-float flag", [&](const std::vector<char>& v, size_t i) {
            return std::memcmp(&v[i], key.data(), key.size()) == 0 && le32(&v[i + key.size()]) == 4 &&
                   std::memcmp(&v[i + key.size() + 4], "bool", 4) == 0 && le32(&v[i + key.size() + 8]) == 1 &&
                   v[i + key.size() + 12] == 1;
        });
        b[at + key.size() + 12] = 0;
        write_bytes(path("half_mismatch.vdb"), b);
    }

    { // NanoVDB: a description claiming a 2^40-byte grid; a root tile's child 2^40 bytes away
        FloatGrid::Ptr g = float_grid("density", 0.1);
        g->tree().setValue(Coord(1, 2, 3), 0.5f);
        auto handle = nanovdb::openToNanoVDB(*g);
        nanovdb::io::writeGrid(path("nano_size.nvdb"), handle);
        b = read_bytes(path("nano_size.nvdb"));
        const uint64_t tib = 1ull << 40;
        std::memcpy(&b[16], &tib, 8); // the first description's gridSize, after the 16-byte header
        write_bytes(path("nano_size.nvdb"), b);
        auto* grid = handle.grid<float>();
        auto* nroot = grid->tree().root().data();
        if (nroot->mTableSize < 1 || !nroot->tile(0)->isChild()) throw std::runtime_error("nano root: no child tile");
        const_cast<nanovdb::NanoRoot<float>::DataType::Tile*>(nroot->tile(0))->child = (int64_t)1 << 40;
        nanovdb::io::writeGrid(path("nano_child.nvdb"), handle);
    }

    b = one_leaf("no_offsets.vdb", 512);
    b[20] = 0; // after the magic, the file version and the library version: "has grid offsets"
    write_bytes(path("no_offsets.vdb"), b);

    b = one_leaf("chunk_raw.vdb", 4);
    // the leaf's 16 bytes of values in a 32-byte blosc chunk: int64 32,
    // then blosc's header (16 bytes uncompressed, 32 compressed)
    at = find_one(b, "small chunk", [&](const std::vector<char>& v, size_t i) {
        int64_t n;
        std::memcpy(&n, &v[i], 8);
        return n == 32 && le32(&v[i + 12]) == 16 && le32(&v[i + 20]) == 32;
    });
    const int64_t more = -4096;
    std::memcpy(&b[at], &more, 8);
    write_bytes(path("chunk_raw.vdb"), b);
}

} // namespace

int main(int argc, char** argv)
{
    if (argc == 3 && (std::strcmp(argv[1], "--plume") == 0 || std::strcmp(argv[1], "--pyro") == 0 ||
                      std::strcmp(argv[1], "--plume-faded") == 0)) {
        std::filesystem::path file(argv[2]);
        g_dir = file.has_parent_path() ? file.parent_path().string() : std::string(".");
        try {
            std::filesystem::create_directories(g_dir);
            openvdb::initialize();
            FloatGrid::Ptr p = plume(std::strcmp(argv[1], "--pyro") == 0 ? 1.0 : 2.2,
                                     std::strcmp(argv[1], "--plume-faded") == 0);
            if (std::strcmp(argv[1], "--pyro") == 0) write(file.filename().string().c_str(), {p, plume_temperature(*p)});
            else write(file.filename().string().c_str(), {p});
        } catch (const std::exception& e) {
            std::fprintf(stderr, "make_test_vdbs: %s\n", e.what());
            return 1;
        }
        std::printf("wrote %s\n", argv[2]);
        return 0;
    }
    if (argc == 3 && std::strcmp(argv[1], "--smoke-vel") == 0) {
        std::filesystem::path file(argv[2]);
        g_dir = file.has_parent_path() ? file.parent_path().string() : std::string(".");
        try {
            std::filesystem::create_directories(g_dir);
            openvdb::initialize();
            write(file.filename().string().c_str(), smoke_with_velocity());
        } catch (const std::exception& e) {
            std::fprintf(stderr, "make_test_vdbs: %s\n", e.what());
            return 1;
        }
        std::printf("wrote %s\n", argv[2]);
        return 0;
    }
    if (argc == 4 && std::strcmp(argv[1], "--pair") == 0) {
        try {
            openvdb::initialize();
            FloatGrid::Ptr a = plume(1.0), b = plume(0.7);
            b->setTransform(openvdb::math::Transform::createLinearTransform(0.03));
            b->transform().postTranslate(openvdb::Vec3d(0.35, 0.5, 0.1));
            for (int i = 0; i < 2; ++i) {
                std::filesystem::path file(argv[2 + i]);
                g_dir = file.has_parent_path() ? file.parent_path().string() : std::string(".");
                std::filesystem::create_directories(g_dir);
                write(file.filename().string().c_str(), {i ? b : a});
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "make_test_vdbs: %s\n", e.what());
            return 1;
        }
        std::printf("wrote %s and %s\n", argv[2], argv[3]);
        return 0;
    }
    if (argc == 3 && std::strcmp(argv[1], "--odd-names") == 0) {
        // grid names a file may hold but a terminal or JSON cannot take as they are (issue 22): an escape
        // sequence, bytes that are not UTF-8 (0xFF, a lone continuation, an overlong '/'), and valid UTF-8
        try {
            openvdb::initialize();
            FloatGrid::Ptr a = float_grid("den\x1b[31msity\xff", 0.1), b = float_grid("caf\xc3\xa9 \x80\xc0\xaf", 0.1);
            a->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
            b->tree().setValue(openvdb::Coord(1, 2, 3), 0.5f);
            openvdb::io::File file(argv[2]);
            file.write({a, b});
            file.close();
        } catch (const std::exception& e) {
            std::fprintf(stderr, "make_test_vdbs: %s\n", e.what());
            return 1;
        }
        std::printf("wrote %s\n", argv[2]);
        return 0;
    }
    if (argc < 2 || argc > 3 || (argc == 3 && std::strcmp(argv[2], "--big") != 0)) {
        std::fprintf(stderr, "usage: %s DIR [--big] | --plume FILE | --plume-faded FILE | --pyro FILE | --smoke-vel FILE | --pair A B | "
                             "--odd-names FILE\n", argv[0]);
        return 2;
    }
    g_dir = argv[1];
    try {
        std::filesystem::create_directories(g_dir);
        openvdb::initialize();
        make_all(argc == 3);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "make_test_vdbs: %s\n", e.what());
        return 1;
    }
    std::printf("wrote the test VDB files into %s\n", g_dir.c_str());
    return 0;
}
