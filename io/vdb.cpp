// veil — the OpenVDB reader (io/vdb.h): with io/vdb_header.cpp, the only C++ in veil.
//
// Every extern "C" function runs its body inside guarded(), which catches
// every exception and turns it into a veil_result and a message; nothing
// C++ crosses the header. Files are opened without delayed loading, so the
// grid is read completely (and a truncated file fails) inside veil_vdb_open,
// never later from a memory-mapped file.
//
// Visibility: veil's own declarations are hidden (libveil.so exports only
// include/'s VEIL_API functions), OpenVDB's are not. The objects are C++
// without -fvisibility=hidden: with it the template code instantiated here
// was hidden, and openvdb::initialize() crashed registering its grid types
// in a program linking libveil.a. The pragma below covers only veil's
// headers; the system headers they use come first, at default visibility.
#include <stddef.h>
#include <stdint.h>
#include <string>
#pragma GCC visibility push(hidden)
#include "vdb.h"
#include "vdb_header.hpp"
#include "../core/text.h"
#include "../scene/limits.h"
extern "C" {
#include "../core/progress.h"
}
#pragma GCC visibility pop

#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/NanoToOpenVDB.h>
#include "nanovdb_check.hpp"
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cJSON.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <memory>
#include <new>
#include <fstream>
#include <vector>
#include <string>

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatGrid;
using openvdb::GridBase;
using openvdb::Vec3SGrid;
using openvdb::Vec3DGrid;

struct veil_vdb {
    std::string path, name;
    FloatGrid::Ptr grid;         // read-only once opened
    CoordBBox active_box;        // computed once: the grid does not change
    openvdb::Index64 active = 0;
    std::string others;          // the file's other grids, "name (type)", comma-separated
    veil_vdb_values values{};    // the active values' range (all finite: checked when opened)
};

struct veil_vdb_velocity {
    std::string path, name;      // name: "vel", or "vel.x/.y/.z" for a float triple
    Vec3SGrid::Ptr grid;         // read-only once placed; inactive values 0
    bool staggered = false;      // GRID_STAGGERED: a MAC grid, sampled with StaggeredBoxSampler
    double lin[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}; // the placements' 3x3 (column vectors): vectors read lin v
    double max = 0.0;            // max |lin v| over the active values
};

namespace {

// Points sampled per parallel task: large enough to amortise a task and its
// value accessor, small enough to balance over cores.
constexpr size_t SAMPLE_GRAIN = 4096;

// A failure whose message is already written for the user.
struct failure {
    veil_result code;
    std::string msg;
};

[[noreturn]] void fail_with(veil_result code, std::string msg) { throw failure{code, std::move(msg)}; }

#if defined(__SANITIZE_ADDRESS__)
#define VEIL_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VEIL_UNDER_ASAN 1
#endif
#endif

bool g_limit_reads = false;       // veil_vdb_limit_reads
unsigned long long g_budget = 0;  // the address-space limit of the read under way (0: none)

// While a file is read, the process's address space is limited to what it
// uses plus 1 GiB plus 64 times the file's size, when veil_vdb_limit_reads
// asked for it (the CLI does): OpenVDB takes buffer sizes inside the trees
// (blosc and zip chunks) from the file and allocates them before reading,
// and a corrupt one asked for 10 GB. Not under AddressSanitizer, whose
// shadow memory reserves terabytes of address space.
class read_budget {
public:
    explicit read_budget(const std::string& path)
    {
#ifndef VEIL_UNDER_ASAN
        struct stat st;
        if (!g_limit_reads || stat(path.c_str(), &st) != 0) return;
        unsigned long long pages = 0;
        if (FILE* f = std::fopen("/proc/self/statm", "r")) {
            if (std::fscanf(f, "%llu", &pages) != 1) pages = 0;
            std::fclose(f);
        }
        if (!pages || getrlimit(RLIMIT_AS, &old_) != 0) return;
        unsigned long long limit = pages * (unsigned long long)sysconf(_SC_PAGESIZE) + (1ull << 30) +
                                   64ull * (unsigned long long)st.st_size;
        if (old_.rlim_cur != RLIM_INFINITY && old_.rlim_cur <= limit) return; // never loosened
        struct rlimit r = old_;
        r.rlim_cur = limit;
        if (setrlimit(RLIMIT_AS, &r) == 0) active_ = true, g_budget = limit;
#else
        (void)path;
#endif
    }
    ~read_budget()
    {
        if (active_) setrlimit(RLIMIT_AS, &old_); // g_budget stays for guarded()'s message; it clears it
    }
    read_budget(const read_budget&) = delete;
    read_budget& operator=(const read_budget&) = delete;

private:
    struct rlimit old_ = {0, 0};
    bool active_ = false;
};

std::string quoted(const std::string& s) { return "'" + s + "'"; }
// (for a non-const string, which std::quoted, found by ADL, would otherwise take)
std::string quoted(std::string& s) { return "'" + s + "'"; }

// A number for a message: "1.2e+31" rather than std::to_string's 32 digits.
std::string number_text(double v)
{
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", v);
    return b;
}

// Runs f, mapping every exception to a result: `what` prefixes the messages
// of exceptions thrown by OpenVDB or the standard library (normally the file).
template <typename F>
veil_result guarded(veil_error* err, const char* what, F&& f) noexcept
{
    struct clear_budget {
        ~clear_budget() { g_budget = 0; }
    } clear;
    try {
        f();
        return VEIL_OK;
    } catch (const failure& e) {
        return veil_fail(err, e.code, "%s", e.msg.c_str());
    } catch (const std::bad_alloc&) {
        if (g_budget)
            return veil_fail(err, VEIL_ERR_IO, "%s: corrupt OpenVDB file: reading it asked for more memory than a file "
                             "of its size can need (the budget: %llu MiB)", what, g_budget >> 20);
        return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory while reading the OpenVDB file", what);
    } catch (const openvdb::Exception& e) {
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot read the OpenVDB file (OpenVDB said: %s)", what, e.what());
    } catch (const std::exception& e) {
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot read the OpenVDB file (%s)", what, e.what());
    } catch (...) {
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot read the OpenVDB file (unknown C++ exception)", what);
    }
}

void init_openvdb()
{
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

// The file must exist and be a regular file; OpenVDB's own message for a
// missing file does not say why.
void check_readable(const std::string& path)
{
    struct stat st;
    if (stat(path.c_str(), &st) != 0) fail_with(VEIL_ERR_IO, path + ": cannot open: " + std::strerror(errno));
    if (S_ISDIR(st.st_mode)) fail_with(VEIL_ERR_IO, path + ": cannot read: Is a directory");
}

// Opens the file with delayed loading off (everything is read now), after
// its header's claims are checked against its size.
void open_file(openvdb::io::File& file, const std::string& path)
{
    init_openvdb();
    check_readable(path);
    std::string why;
    if (!veil__vdb_header_ok(path, &why)) fail_with(VEIL_ERR_IO, path + ": " + why);
    file.open(false);
}

// Before OpenVDB reads a grid's tree: the tree's counts, masks and chunk
// sizes checked against the grid's bytes (io/vdb_header.cpp).
void check_tree(const std::string& path, const std::string& grid)
{
    std::string why;
    if (!veil__vdb_tree_ok(path, grid, &why)) fail_with(VEIL_ERR_IO, path + ": " + why);
}

std::string class_name(const GridBase& g)
{
    switch (g.getGridClass()) {
    case openvdb::GRID_LEVEL_SET: return "level set";
    case openvdb::GRID_FOG_VOLUME: return "fog volume";
    case openvdb::GRID_STAGGERED: return "staggered";
    default: return "unknown";
    }
}

// "temperature (float, fog volume), velocity (vec3s, unknown)"
std::string list_grids(const openvdb::GridPtrVec& grids)
{
    std::string s;
    for (const auto& g : grids) {
        if (!s.empty()) s += ", ";
        s += quoted(g->getName()) + " (" + g->valueType() + ", " + class_name(*g) + ")";
    }
    return s.empty() ? "no grids" : s;
}

// A NanoVDB file (.nvdb, as pbrt-v4's scenes ship): by its name's suffix.
bool is_nanovdb(const std::string& path)
{
    if (path.size() < 5) return false;
    std::string ext = path.substr(path.size() - 5);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return (char)std::tolower(c); });
    return ext == ".nvdb";
}

// Every grid of a NanoVDB file, converted to an OpenVDB grid with its tree
// (nanovdb::nanoToOpenVDB; a quantised Fp4/8/16/N grid becomes a float grid
// of its decoded values), named and classed as in the file. A grid of a
// type the converter does not know (points, indices) is left out. The
// grids are complete: the callers treat them as read.
// A grid of NanoVDB build type T, its nodes checked first (io/nanovdb_check.hpp).
template <typename T>
GridBase::Ptr nano_to_openvdb(const nanovdb::GridHandle<nanovdb::HostBuffer>& h)
{
    const auto& grid = *reinterpret_cast<const nanovdb::NanoGrid<T>*>(h.data());
    veil_nano::grid_ok(grid, h.size());
    return nanovdb::nanoToOpenVDB(grid);
}

openvdb::GridPtrVec read_nanovdb(const std::string& path)
{
    init_openvdb();
    check_readable(path);
    std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
    try {
        veil_nano::file_ok(path);
        handles = nanovdb::io::readGrids(path);
    } catch (const std::string& why) {
        fail_with(VEIL_ERR_IO, path + ": " + why);
    } catch (const std::exception& e) {
        fail_with(VEIL_ERR_IO, path + ": cannot read the NanoVDB file: " + e.what());
    }
    if (handles.empty()) fail_with(VEIL_ERR_IO, path + ": cannot read the NanoVDB file: it holds no grid");
    openvdb::GridPtrVec out;
    for (const auto& h : handles) {
        if (h.size() < sizeof(nanovdb::GridData)) continue; // file_ok: not from a file
        const auto* d = reinterpret_cast<const nanovdb::GridData*>(h.data());
        if (!std::memchr(d->mGridName, 0, sizeof d->mGridName))
            fail_with(VEIL_ERR_IO, path + ": truncated or corrupt NanoVDB file: a grid name without its end");
        GridBase::Ptr g;
        try {
            using nanovdb::GridType;
            switch (d->mGridType) {
            case GridType::Float: g = nano_to_openvdb<float>(h); break;
            case GridType::Double: g = nano_to_openvdb<double>(h); break;
            case GridType::Int32: g = nano_to_openvdb<int32_t>(h); break;
            case GridType::Int64: g = nano_to_openvdb<int64_t>(h); break;
            case GridType::Boolean: g = nano_to_openvdb<bool>(h); break;
            case GridType::Mask: g = nano_to_openvdb<nanovdb::ValueMask>(h); break;
            case GridType::Vec3f: g = nano_to_openvdb<nanovdb::Vec3f>(h); break;
            case GridType::Vec3d: g = nano_to_openvdb<nanovdb::Vec3d>(h); break;
            case GridType::Vec4f: g = nano_to_openvdb<nanovdb::Vec4f>(h); break;
            case GridType::Vec4d: g = nano_to_openvdb<nanovdb::Vec4d>(h); break;
            case GridType::Fp4: g = nano_to_openvdb<nanovdb::Fp4>(h); break;
            case GridType::Fp8: g = nano_to_openvdb<nanovdb::Fp8>(h); break;
            case GridType::Fp16: g = nano_to_openvdb<nanovdb::Fp16>(h); break;
            case GridType::FpN: g = nano_to_openvdb<nanovdb::FpN>(h); break;
            default: continue; // a type with no OpenVDB counterpart
            }
        } catch (const std::string& why) {
            fail_with(VEIL_ERR_IO, path + ": grid '" + d->mGridName + "': " + why);
        } catch (const openvdb::RuntimeError&) {
            continue; // a type with no OpenVDB counterpart
        }
        if (!g) continue;
        const nanovdb::GridMetaData* m = h.gridMetaData();
        g->setName(m->shortGridName());
        if (m->isLevelSet()) g->setGridClass(openvdb::GRID_LEVEL_SET);
        else if (m->isFogVolume()) g->setGridClass(openvdb::GRID_FOG_VOLUME);
        out.push_back(g);
    }
    return out;
}

// The grids of a file: an OpenVDB file's metadata (file is opened, the trees
// are read on demand), or a NanoVDB file's grids whole (file is not used).
openvdb::GridPtrVec file_grids(openvdb::io::File& file, const std::string& path, bool nano)
{
    if (nano) return read_nanovdb(path);
    open_file(file, path);
    return *file.readAllGridMetadata();
}

// The grid to load: the named one, or the default (see vdb.h).
GridBase::Ptr choose(const std::string& path, const openvdb::GridPtrVec& grids, const char* want)
{
    if (want) {
        for (const auto& g : grids)
            if (g->getName() == want) return g;
        fail_with(VEIL_ERR_INVALID, path + ": no grid named " + quoted(want) + "; the file has " + list_grids(grids));
    }
    for (const auto& g : grids)
        if (g->getName() == VEIL_VDB_DEFAULT_GRID) return g;
    for (const auto& g : grids)
        if (g->isType<FloatGrid>()) return g;
    fail_with(VEIL_ERR_INVALID, path + ": no float grid to read (veil reads a scalar float density grid, by default "
                                       "the one named '" VEIL_VDB_DEFAULT_GRID "'); the file has " + list_grids(grids));
}

// Inactive values (voxels, tiles, background) become 0: only active voxels
// carry density. Fog volumes already have this form. Each leaf's inactive
// voxels are found from its mask and its buffer written directly; a tree
// iterator over every inactive value (the tiles' too) took 7-10 ms of the
// 18 ms it takes to open the shared smoke.vdb, this 3 ms.
// (A velocity grid's too: its inactive vectors read 0.)
template <typename GridT>
void zero_inactive(GridT& grid)
{
    using V = typename GridT::ValueType;
    const V zero = openvdb::zeroVal<V>();
    typename GridT::TreeType& tree = grid.tree();
    if (tree.background() != zero) tree.root().setBackground(zero, true);
    for (auto leaf = tree.beginLeaf(); leaf; ++leaf) {
        V* d = leaf->buffer().data();
        for (auto off = leaf->getValueMask().beginOff(); off; ++off) d[off.pos()] = zero;
    }
    typename GridT::ValueOffIter it = grid.beginValueOff();
    it.setMaxDepth(GridT::ValueOffIter::LEAF_DEPTH - 1); // the inactive tiles above the leaves
    for (; it; ++it)
        if (*it != zero) it.setValue(zero);
}

// Calls f(value, voxels, leaf, offset[, coord]) for every value a voxel
// reads: each leaf's whole buffer (its inactive values are 0 by now:
// zero_inactive), then the active tiles above the leaves (voxels: the
// tile's voxel count, leaf NULL, coord its origin). For the refusals'
// counts and indices; scan_values below is the fast pass.
template <typename F>
void each_value(const FloatGrid& grid, F&& f)
{
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
        const float* d = leaf->buffer().data();
        for (openvdb::Index i = 0; i < FloatGrid::TreeType::LeafNodeType::SIZE; ++i)
            f(d[i], 1, leaf.getLeaf(), i);
    }
    FloatGrid::ValueOnCIter it = grid.cbeginValueOn();
    it.setMaxDepth(FloatGrid::ValueOnCIter::LEAF_DEPTH - 1); // tiles only
    for (; it; ++it) f(*it, it.getVoxelCount(), nullptr, (openvdb::Index)0, it.getCoord());
}

// The values' range, 0 included, and how many voxels are below 0; a value
// that is not a number or infinite is refused, with how many voxels hold
// one and where the first is (scene/limits.h: one pass over the values
// already in memory, each leaf's buffer as an array the compiler
// vectorises: 1.6 ms for the 3 117 leaves of the shared smoke.vdb; a tree
// iterator over its active voxels took 6-10 ms).
veil_vdb_values scan_values(const FloatGrid& grid, const std::string& where)
{
    using Leaf = FloatGrid::TreeType::LeafNodeType;
    veil_vdb_values out{};
    openvdb::Index64 bad = 0;
    float lo = 0.0f, hi = 0.0f;
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
        const float* d = leaf->buffer().data();
        float l = 0.0f, h = 0.0f;
        unsigned neg = 0, nonfinite = 0;
        for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
            const float x = d[i];
            nonfinite += !(x - x == 0.0f); // NaN for NaN and +-inf
            neg += x < 0.0f;
            l = x < l ? x : l;
            h = x > h ? x : h;
        }
        bad += nonfinite, out.negative += neg;
        lo = std::min(lo, l), hi = std::max(hi, h);
    }
    FloatGrid::ValueOnCIter tile = grid.cbeginValueOn();
    tile.setMaxDepth(FloatGrid::ValueOnCIter::LEAF_DEPTH - 1); // the active tiles above the leaves
    for (; tile; ++tile) {
        const float x = *tile;
        if (!std::isfinite(x)) bad += tile.getVoxelCount();
        else if (x < 0.0f) out.negative += tile.getVoxelCount();
        if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
    }
    if (bad > 0) {
        Coord first;
        float first_value = 0.0f;
        each_value(grid, [&](float x, openvdb::Index64, const Leaf* leaf, openvdb::Index i, Coord c = Coord()) {
            if (!std::isfinite(x) && std::isfinite(first_value)) first = leaf ? leaf->offsetToGlobalCoord(i) : c, first_value = x;
        });
        char text[32];
        fail_with(VEIL_ERR_INVALID,
                  where + ": " + std::to_string(bad) + (bad == 1 ? " voxel is" : " voxels are") +
                      " not a number or infinite (" + (bad == 1 ? "" : "the first ") + "at index [" +
                      std::to_string(first[0]) + ", " + std::to_string(first[1]) + ", " + std::to_string(first[2]) +
                      "]: " + veil_number_text(first_value, text, sizeof text) +
                      "); veil reads finite values only (scene/limits.h)");
    }
    out.min = lo, out.max = hi;
    return out;
}

void to_column_matrix(const openvdb::math::Transform& t, double m[4][4])
{
    const openvdb::Mat4d a = t.baseMap()->getAffineMap()->getMat4(); // row vectors: world = idx * a
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[r][c] = a(c, r);
}

// World AABB of the 8 corners of an index box under an affine map.
void world_box(const double m[4][4], const CoordBBox& b, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; ++a) {
        lo[a] = HUGE_VAL;
        hi[a] = -HUGE_VAL;
    }
    for (int c = 0; c < 8; ++c) {
        const double p[3] = {(double)(c & 1 ? b.max().x() : b.min().x()), (double)(c & 2 ? b.max().y() : b.min().y()),
                             (double)(c & 4 ? b.max().z() : b.min().z())};
        for (int r = 0; r < 3; ++r) {
            double w = m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3];
            lo[r] = std::min(lo[r], w);
            hi[r] = std::max(hi[r], w);
        }
    }
}

void copy_name(const std::string& s, char* out, size_t len)
{
    if (!out || len == 0) return;
    size_t n = std::min(s.size(), len - 1);
    std::memcpy(out, s.data(), n);
    out[n] = '\0';
}

char* dup_c(const std::string& s)
{
    char* p = static_cast<char*>(std::malloc(s.size() + 1));
    if (!p) throw std::bad_alloc();
    std::memcpy(p, s.c_str(), s.size() + 1);
    return p;
}

void fill_info(const std::string& path, openvdb::io::File* file, const GridBase& meta, veil_vdb_grid_info& gi)
{
    gi.name = dup_c(meta.getName());
    copy_name(class_name(meta), gi.grid_class, sizeof gi.grid_class);
    copy_name(meta.valueType(), gi.value_type, sizeof gi.value_type);

    CoordBBox box;
    openvdb::Index64 count = 0;
    // The statistics OpenVDB writes by default (absent, or of another
    // type, in files written otherwise: then the tree is read).
    const auto bmin = meta.getMetadata<openvdb::Vec3IMetadata>(GridBase::META_FILE_BBOX_MIN);
    const auto bmax = meta.getMetadata<openvdb::Vec3IMetadata>(GridBase::META_FILE_BBOX_MAX);
    const auto cnt = meta.getMetadata<openvdb::Int64Metadata>(GridBase::META_FILE_VOXEL_COUNT);
    if (!file) { // a grid read whole (NanoVDB): its tree is here
        count = meta.activeVoxelCount();
        box = meta.evalActiveVoxelBoundingBox();
    } else if (bmin && bmax && cnt) {
        count = (openvdb::Index64)cnt->value();
        box = CoordBBox(Coord(bmin->value()), Coord(bmax->value()));
    } else { // written without statistics: read the tree
        check_tree(path, meta.getName());
        GridBase::Ptr g = file->readGrid(meta.getName());
        count = g->activeVoxelCount();
        box = g->evalActiveVoxelBoundingBox();
    }
    gi.active_voxels = count;
    for (int a = 0; a < 3; ++a) {
        gi.index_lo[a] = count ? box.min()[a] : 0;
        gi.index_hi[a] = count ? box.max()[a] : -1;
    }

    const openvdb::math::Transform& t = meta.transform();
    const openvdb::Vec3d vs = t.voxelSize();
    for (int a = 0; a < 3; ++a) gi.voxel_size[a] = vs[a];
    copy_name(t.baseMap()->type(), gi.map_type, sizeof gi.map_type);
    gi.affine = t.baseMap()->isLinear() ? 1 : 0;
    if (gi.affine) {
        to_column_matrix(t, gi.index_to_world);
        if (count) world_box(gi.index_to_world, box, gi.world_lo, gi.world_hi);
    }
}

// Gives grid the index-to-world map m (column vectors, last row 0 0 0 1),
// refusing a singular or non-finite one (the reader and the resampler
// invert it).
void place(GridBase& grid, const double m[4][4], const char* label)
{
    openvdb::Mat4d a; // row vectors: world = idx * a, so a is m transposed
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            if (!std::isfinite(m[r][c])) fail_with(VEIL_ERR_INVALID, std::string(label) + ": the index-to-world matrix "
                                                   "holds a value that is not finite");
            a(c, r) = m[r][c];
        }
    if (m[3][0] != 0.0 || m[3][1] != 0.0 || m[3][2] != 0.0 || m[3][3] != 1.0)
        fail_with(VEIL_ERR_INVALID, std::string(label) + ": the index-to-world matrix's last row is not 0 0 0 1 "
                                                         "(veil takes affine maps)");
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    double scale = 0.0; // the largest column length: a det below 1e-12 scale^3 is singular at double precision
    for (int c = 0; c < 3; ++c) scale = std::max(scale, std::sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]));
    if (!(std::fabs(det) > 1e-12 * scale * scale * scale))
        fail_with(VEIL_ERR_INVALID, std::string(label) + ": the index-to-world matrix is singular (determinant " +
                                        std::to_string(det) + "): a voxel would have no volume");
    if (!(std::fabs(det) >= VEIL_MIN_VOXEL_VOLUME)) // OpenVDB's AffineMap would throw "nearly singular"
        fail_with(VEIL_ERR_INVALID, std::string(label) + ": the index-to-world matrix makes a voxel of " +
                                        number_text(std::fabs(det)) + " m^3, under the " +
                                        number_text(VEIL_MIN_VOXEL_VOLUME) +
                                        " m^3 (a cube of 14.4 um) OpenVDB's maps hold (scene/limits.h)");
    double far = 0.0, edge = HUGE_VAL;
    for (int c = 0; c < 3; ++c) edge = std::min(edge, std::sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]));
    for (int r = 0; r < 3; ++r) { // index (0, 0, 0) within the scene's coordinates
        if (!(std::fabs(m[r][3]) <= VEIL_MAX_COORD))
            fail_with(VEIL_ERR_INVALID, std::string(label) + ": the index-to-world matrix puts index (0, 0, 0) at " +
                                            "xyz"[r] + std::string(" = ") + number_text(m[r][3]) +
                                            " m, beyond the scene's +-1e15 m (scene/limits.h)");
        far = std::max(far, std::fabs(m[r][3]));
    }
    if (!(edge >= VEIL_MIN_VOXEL_RELATIVE * far)) // single-precision positions past here: VEIL_MIN_VOXEL_RELATIVE
        fail_with(VEIL_ERR_INVALID, std::string(label) + ": the index-to-world matrix makes voxels of " +
                                        number_text(edge) + " m at " + number_text(far) +
                                        " m from the origin, under 2^-20 of that distance: finer than "
                                        "single-precision positions resolve there (scene/limits.h)");
    grid.setTransform(openvdb::math::Transform::createLinearTransform(a));
}

cJSON* json_ints(const int v[3])
{
    return cJSON_CreateIntArray(v, 3);
}

cJSON* json_doubles(const double v[3])
{
    return cJSON_CreateDoubleArray(v, 3);
}

cJSON* json_pair(cJSON* a, cJSON* b)
{
    cJSON* p = cJSON_CreateArray();
    cJSON_AddItemToArray(p, a);
    cJSON_AddItemToArray(p, b);
    return p;
}

// A string of the file as JSON can hold it: its bytes that are not UTF-8
// become U+FFFD (core/text.h); cJSON escapes the control characters.
cJSON* add_text(cJSON* o, const char* key, const char* text)
{
    std::string out(3 * strlen(text) + 1, '\0');
    veil_text_utf8(text, &out[0], out.size());
    return cJSON_AddStringToObject(o, key, out.c_str());
}

cJSON* grid_json(const veil_vdb_grid_info& g)
{
    cJSON* o = cJSON_CreateObject();
    add_text(o, "name", g.name);
    add_text(o, "class", g.grid_class);
    add_text(o, "value_type", g.value_type);
    cJSON_AddNumberToObject(o, "active_voxels", (double)g.active_voxels);
    const bool empty = g.active_voxels == 0;
    cJSON_AddItemToObject(o, "index_bbox", empty ? cJSON_CreateNull() : json_pair(json_ints(g.index_lo), json_ints(g.index_hi)));
    cJSON_AddItemToObject(o, "world_bbox", empty || !g.affine ? cJSON_CreateNull()
                                                              : json_pair(json_doubles(g.world_lo), json_doubles(g.world_hi)));
    cJSON_AddItemToObject(o, "voxel_size", json_doubles(g.voxel_size));
    add_text(o, "map_type", g.map_type);
    if (g.affine) {
        cJSON* m = cJSON_CreateArray();
        for (int r = 0; r < 4; ++r) cJSON_AddItemToArray(m, cJSON_CreateDoubleArray(g.index_to_world[r], 4));
        cJSON_AddItemToObject(o, "transform", m);
    } else {
        cJSON_AddItemToObject(o, "transform", cJSON_CreateNull());
    }
    return o;
}


// ---- velocity (veil_vdb_velocity_*) -------------------------------------

GridBase::Ptr find_grid(const openvdb::GridPtrVec& grids, const std::string& name)
{
    for (const auto& g : grids)
        if (g->getName() == name) return g;
    return nullptr;
}

bool is_vector(const GridBase& g) { return g.isType<Vec3SGrid>() || g.isType<Vec3DGrid>(); }

// The most voxels of one active tile a float triple's tile is expanded into
// (a triple is merged voxel by voxel; vector grids keep their tiles): a
// 128^3 tile, the largest below a 4096^3 root tile.
constexpr openvdb::Index64 TRIPLE_MAX_TILE = openvdb::Index64(128) * 128 * 128;

// The velocity the file's grid (or the triple's three) hold, as a vec3s grid
// with 0 where inactive: a vec3d grid's vectors rounded to float (a vector
// beyond float becomes infinite and is refused by scan_velocity).
Vec3SGrid::Ptr as_vec3s(const GridBase::Ptr& g)
{
    if (Vec3SGrid::Ptr s = openvdb::gridPtrCast<Vec3SGrid>(g)) return s;
    Vec3DGrid::Ptr d = openvdb::gridPtrCast<Vec3DGrid>(g);
    Vec3SGrid::Ptr out = Vec3SGrid::create(openvdb::Vec3s(0.0f));
    out->setTransform(d->transform().copy());
    out->setGridClass(d->getGridClass());
    Vec3SGrid::Accessor acc = out->getAccessor();
    for (auto it = d->cbeginValueOn(); it; ++it) {
        const openvdb::Vec3d x = *it;
        const openvdb::Vec3s v((float)x[0], (float)x[1], (float)x[2]);
        if (it.isVoxelValue()) {
            acc.setValue(it.getCoord(), v);
        } else {
            CoordBBox b;
            it.getBoundingBox(b);
            out->tree().fill(b, v, true);
        }
    }
    return out;
}

Vec3SGrid::Ptr merge_triple(const FloatGrid::Ptr c[3], const std::string& where)
{
    for (int a = 1; a < 3; ++a)
        if (!(c[a]->transform() == c[0]->transform()))
            fail_with(VEIL_ERR_INVALID, where + ": its three float grids have different transforms; a velocity triple "
                                                "needs one lattice");
    Vec3SGrid::Ptr out = Vec3SGrid::create(openvdb::Vec3s(0.0f));
    out->setTransform(c[0]->transform().copy());
    Vec3SGrid::Accessor acc = out->getAccessor();
    for (int a = 0; a < 3; ++a)
        for (auto it = c[a]->cbeginValueOn(); it; ++it) {
            CoordBBox b;
            it.getBoundingBox(b);
            if (b.volume() > TRIPLE_MAX_TILE)
                fail_with(VEIL_ERR_INVALID, where + ": an active tile of " + std::to_string(b.volume()) +
                                                " voxels in a float triple (at most a 128^3 tile is merged; store the "
                                                "velocity as a vec3 grid)");
            for (auto p = b.begin(); p; ++p) {
                openvdb::Vec3s v = acc.getValue(*p);
                v[a] = *it;
                acc.setValue(*p, v);
            }
        }
    return out;
}

// The largest |lin v| over the active vectors, refusing one that is not finite.
void scan_velocity(veil_vdb_velocity& v)
{
    double most = 0.0;
    for (auto it = v.grid->cbeginValueOn(); it; ++it) {
        const openvdb::Vec3s x = *it;
        double w[3], n2 = 0.0;
        for (int r = 0; r < 3; ++r) {
            w[r] = v.lin[r][0] * x[0] + v.lin[r][1] * x[1] + v.lin[r][2] * x[2];
            n2 += w[r] * w[r];
        }
        if (!std::isfinite(n2)) {
            const Coord c = it.getCoord();
            fail_with(VEIL_ERR_INVALID, v.path + ": grid " + quoted(v.name) + ": a velocity at index [" +
                                            std::to_string(c[0]) + ", " + std::to_string(c[1]) + ", " +
                                            std::to_string(c[2]) +
                                            "] is not a finite vector; veil reads finite values only (scene/limits.h)");
        }
        most = std::max(most, n2);
    }
    v.max = std::sqrt(most);
}

// What the file holds under `name`: a vec3 grid (returned), or the float
// triple name.x/.y/.z (its names in triple[]), or nothing (both empty).
GridBase::Ptr velocity_candidate(const openvdb::GridPtrVec& grids, const std::string& name, std::string triple[3])
{
    GridBase::Ptr g = find_grid(grids, name);
    if (g && is_vector(*g)) return g;
    int found = 0;
    for (int a = 0; a < 3; ++a) {
        GridBase::Ptr c = find_grid(grids, name + "." + "xyz"[a]);
        if (c && c->isType<FloatGrid>()) triple[a] = c->getName(), ++found;
    }
    if (found < 3)
        for (int a = 0; a < 3; ++a) triple[a].clear();
    return nullptr;
}

// ---- advection (veil_vdb_advect_mean) ----------------------------------

// A displacement of more voxels than this is refused before any work: the
// region grows by it on every side (VEIL_VDB_ADVECT_MAX_VOXELS bounds the
// result; this keeps the reach an int with room).
constexpr double ADVECT_MAX_REACH = 1 << 20;

// g's active region grown by `reach` voxels on every side, as active tiles
// and voxels of value 0 in a grid on g's transform (sparseFill makes
// tiles where a whole node is covered, so the count is cheap before any
// voxel exists).
FloatGrid::Ptr grown_topology(const FloatGrid& g, int reach)
{
    FloatGrid::Ptr out = FloatGrid::create(0.0f);
    out->setTransform(g.transform().copy());
    for (auto leaf = g.tree().cbeginLeaf(); leaf; ++leaf) {
        CoordBBox b; // the leaf's active voxels' box (tighter than the node's at the grid's edge)
        leaf->evalActiveBoundingBox(b, true);
        if (b.empty()) continue;
        b.expand(reach);
        out->tree().sparseFill(b, 0.0f, true);
    }
    FloatGrid::ValueOnCIter it = g.cbeginValueOn();
    it.setMaxDepth(FloatGrid::ValueOnCIter::LEAF_DEPTH - 1); // the active tiles above the leaves
    for (; it; ++it) {
        CoordBBox b;
        it.getBoundingBox(b);
        b.expand(reach);
        out->tree().sparseFill(b, 0.0f, true);
    }
    return out;
}

// Floor of c / b for a power of two b (and negative c).
openvdb::Coord block_of(const Coord& c, int b)
{
    auto f = [b](int v) { return v >= 0 ? v / b : -((-v + b - 1) / b); };
    return Coord(f(c.x()), f(c.y()), f(c.z()));
}

// The grown region's voxels at most (veil_vdb_advect_work): each leaf's and active tile's box grown by
// reach, rounded out to blocks of b voxels, their union counted on a mask; stops (at_least) once the
// union passes `stop` voxels.
void count_grown(const FloatGrid& g, int reach, double stop, double& voxels, int& at_least)
{
    int b = 8;
    while (b < reach / 32) b *= 2;
    const double block = (double)b * b * b;
    openvdb::MaskGrid::Ptr mask = openvdb::MaskGrid::create();
    size_t boxes = 0;
    voxels = 0.0, at_least = 0;
    auto add = [&](CoordBBox box) {
        box.expand(reach);
        mask->tree().sparseFill(CoordBBox(block_of(box.min(), b), block_of(box.max(), b)), true, true);
        if (++boxes % 256 == 0 && (double)mask->tree().activeVoxelCount() * block > stop) at_least = 1;
    };
    for (auto leaf = g.tree().cbeginLeaf(); leaf && !at_least; ++leaf) {
        CoordBBox box;
        leaf->evalActiveBoundingBox(box, true);
        if (!box.empty()) add(box);
    }
    FloatGrid::ValueOnCIter it = g.cbeginValueOn();
    it.setMaxDepth(FloatGrid::ValueOnCIter::LEAF_DEPTH - 1);
    for (; it && !at_least; ++it) {
        CoordBBox box;
        it.getBoundingBox(box);
        add(box);
    }
    voxels = (double)mask->tree().activeVoxelCount() * block;
    if (voxels > stop) at_least = 1;
}

// The checks of a description shared by veil_vdb_advect_work_of and veil_vdb_advect_mean (NULL: fine).
const char* bad_advect_desc(const veil_vdb_advect_desc* d)
{
    if (!d->times) return "no times";
    if (d->n < 1 || d->n > VEIL_VDB_ADVECT_MAX_TIMES || !(d->scale >= 0.0) || !std::isfinite(d->scale) ||
        !(d->max_step_voxels > 0.0) || !std::isfinite(d->max_step_voxels))
        return "bad description";
    for (int k = 0; k < d->n; ++k)
        if (!std::isfinite(d->times[k])) return "a time is not finite";
    return nullptr;
}

// The paths every voxel walks (veil_vdb_advect_mean): the same for all of them, as they depend on the
// times alone. Each side of t = 0 walked outwards (times >= 0 ascending, times < 0 descending), its span
// to each time in equal steps of at most step_time.
struct advect_plan {
    double m[4][4];   // g's index-to-world (column vectors)
    double edge;      // the smallest voxel edge: a column's length
    double speed;     // voxels per unit of time, at most
    int reach = 0;
    double displacement = 0.0; // max|v| scale max|t_k| / edge
    std::vector<double> pos, neg;
    double step_time = 0.0;
    double reads_per_voxel = 0.0; // velocity reads (one at x, one a step) and the n samples of g
};

advect_plan plan_paths(const veil_vdb& g, const veil_vdb_velocity& vel, const veil_vdb_advect_desc& d,
                       const std::string& where)
{
    advect_plan p;
    const openvdb::math::Transform& xf = g.grid->transform();
    if (!xf.baseMap()->isLinear())
        fail_with(VEIL_ERR_INVALID, where + " has a non-affine transform (" + xf.baseMap()->type() + ")");
    to_column_matrix(xf, p.m);
    p.edge = HUGE_VAL;
    for (int c = 0; c < 3; ++c)
        p.edge = std::min(p.edge, std::sqrt(p.m[0][c] * p.m[0][c] + p.m[1][c] * p.m[1][c] + p.m[2][c] * p.m[2][c]));
    double tmax = 0.0;
    for (int k = 0; k < d.n; ++k) tmax = std::max(tmax, std::fabs(d.times[k]));
    p.speed = vel.max * d.scale / p.edge;
    p.displacement = p.speed * tmax;
    if (!(p.displacement > 0.0)) return p; // nothing moves
    if (!(p.displacement <= ADVECT_MAX_REACH))
        fail_with(VEIL_ERR_LIMIT, where + ": motion blur moves it up to " + number_text(p.displacement) +
                                      " voxels (at most " + std::to_string((long)ADVECT_MAX_REACH) +
                                      "): check the velocity's unit and scale");
    p.reach = (int)std::ceil(p.displacement) + 1;
    for (int k = 0; k < d.n; ++k) (d.times[k] >= 0.0 ? p.pos : p.neg).push_back(d.times[k]);
    std::sort(p.pos.begin(), p.pos.end());
    std::sort(p.neg.begin(), p.neg.end(), [](double a, double b) { return a > b; });
    p.step_time = d.max_step_voxels / p.speed; // the longest step (speed > 0 here)
    p.reads_per_voxel = 1.0 + d.n;
    for (const std::vector<double>* side : {&p.pos, &p.neg}) {
        double t = 0.0;
        for (double tk : *side) {
            if (tk != t) p.reads_per_voxel += std::max(1.0, std::ceil(std::fabs(tk - t) / p.step_time));
            t = tk;
        }
    }
    return p;
}

// g with its values below 0 read as 0 (a copy; g when it has none).
FloatGrid::ConstPtr clamped(const veil_vdb& g)
{
    if (g.values.negative == 0) return g.grid;
    FloatGrid::Ptr c = g.grid->deepCopy();
    for (auto leaf = c->tree().beginLeaf(); leaf; ++leaf) {
        float* d = leaf->buffer().data();
        for (openvdb::Index i = 0; i < FloatGrid::TreeType::LeafNodeType::SIZE; ++i) d[i] = std::max(d[i], 0.0f);
    }
    FloatGrid::ValueOnIter it = c->beginValueOn();
    it.setMaxDepth(FloatGrid::ValueOnIter::LEAF_DEPTH - 1);
    for (; it; ++it)
        if (*it < 0.0f) it.setValue(0.0f);
    return c;
}

// The velocity at index point y of g (in g's index space: the field's
// vector, placed, scaled and turned into g's index units: k v).
struct velocity_at {
    const veil_vdb_velocity& vel;
    const openvdb::math::Transform& g_xform; // g's index -> world
    bool same;                               // the field shares g's transform: sampled in index space
    double k[3][3];                          // index displacement per unit of raw vector (scale included)
    Vec3SGrid::ConstAccessor acc;

    openvdb::Vec3d operator()(const openvdb::Vec3d& y)
    {
        const openvdb::Vec3d p = same ? y : vel.grid->transform().worldToIndex(g_xform.indexToWorld(y));
        const openvdb::Vec3s v = vel.staggered ? openvdb::tools::StaggeredBoxSampler::sample(acc, p)
                                               : openvdb::tools::BoxSampler::sample(acc, p);
        openvdb::Vec3d d;
        for (int r = 0; r < 3; ++r) d[r] = k[r][0] * v[0] + k[r][1] * v[1] + k[r][2] * v[2];
        return d;
    }
};

} // namespace

extern "C" {

veil_result veil_vdb_open(const char* path, const char* grid_name, int level_set_to_fog, veil_vdb** out,
                          char* chosen_name, size_t chosen_len, veil_error* err)
{
    if (out) *out = nullptr;
    if (!path || !out) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_open: path and out are required");
    veil_vdb* v = nullptr;
    veil_result r = guarded(err, path, [&] {
        read_budget budget(path);
        const bool nano = is_nanovdb(path);
        openvdb::io::File file(path);
        openvdb::GridPtrVec metas = file_grids(file, path, nano);
        GridBase::Ptr meta = choose(path, metas, grid_name);
        const std::string name = meta->getName(), where = std::string(path) + ": grid " + quoted(name);
        if (!meta->isType<FloatGrid>())
            fail_with(VEIL_ERR_INVALID, where + " has value type " + meta->valueType() +
                                            "; veil reads only float grids (a scalar density)");
        if (meta->getGridClass() == openvdb::GRID_LEVEL_SET && !level_set_to_fog)
            fail_with(VEIL_ERR_INVALID,
                      where + " is a level set (a signed distance to a surface, not a density); add \"level_set\": "
                              "\"to_fog\" to the vdb source to convert it into a fog volume when it is read, or "
                              "convert the file with vdb_tool -ls2fog");
        if (!nano) check_tree(path, name);
        FloatGrid::Ptr grid = openvdb::gridPtrCast<FloatGrid>(nano ? meta : file.readGrid(name));
        if (!nano) file.close();
        if (!grid) fail_with(VEIL_ERR_IO, where + ": OpenVDB returned no float grid");
        if (grid->getGridClass() == openvdb::GRID_LEVEL_SET) openvdb::tools::sdfToFogVolume(*grid);
        zero_inactive(*grid);
        const veil_vdb_values values = scan_values(*grid, where);
        std::string others;
        for (const auto& g : metas)
            if (g->getName() != name) others += (others.empty() ? "" : ", ") + g->getName() + " (" + g->valueType() + ")";
        v = new veil_vdb{path, name, grid, grid->evalActiveVoxelBoundingBox(), grid->activeVoxelCount(), others, values};
    });
    if (r != VEIL_OK) return r;
    copy_name(v->name, chosen_name, chosen_len);
    *out = v;
    return VEIL_OK;
}

void veil_vdb_limit_reads(int on) { g_limit_reads = on != 0; }

void veil_vdb_close(veil_vdb* v)
{
    delete v; // destructors of shared_ptr and std::string do not throw
}

const char* veil_vdb_path(const veil_vdb* v) { return v ? v->path.c_str() : ""; }
const char* veil_vdb_grid_name(const veil_vdb* v) { return v ? v->name.c_str() : ""; }
const char* veil_vdb_other_grids(const veil_vdb* v) { return v ? v->others.c_str() : ""; }

void veil_vdb_value_range(const veil_vdb* v, veil_vdb_values* out)
{
    if (out) *out = v ? v->values : veil_vdb_values{};
}

uint64_t veil_vdb_count_outside(const veil_vdb* v, double lo, double hi)
{
    uint64_t n = 0;
    if (v)
        each_value(*v->grid, [&](float x, openvdb::Index64 k, const void*, openvdb::Index, Coord = Coord()) {
            if (x < lo || x > hi) n += k;
        });
    return n;
}

veil_result veil_vdb_transform(const veil_vdb* v, double index_to_world[4][4], veil_error* err)
{
    if (!v) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_transform: no grid");
    return guarded(err, v->path.c_str(), [&] {
        const openvdb::math::Transform& t = v->grid->transform();
        if (!t.baseMap()->isLinear())
            fail_with(VEIL_ERR_INVALID, v->path + ": grid " + quoted(v->name) + " has a non-affine transform (" +
                                            t.baseMap()->type() +
                                            "); veil reads grids whose index-to-world map is affine (scale, rotation, "
                                            "shear, translation), not frustum or other nonlinear maps");
        to_column_matrix(t, index_to_world);
    });
}

veil_result veil_vdb_index_bbox(const veil_vdb* v, int lo[3], int hi[3], size_t* active_voxels)
{
    if (!v) return VEIL_ERR_INVALID;
    for (int a = 0; a < 3; ++a) {
        lo[a] = v->active ? v->active_box.min()[a] : 0;
        hi[a] = v->active ? v->active_box.max()[a] : -1;
    }
    if (active_voxels) *active_voxels = (size_t)v->active;
    return VEIL_OK;
}

veil_result veil_vdb_sample_world(const veil_vdb* v, const double* xyz, size_t n, float* out, veil_error* err)
{
    if (!v || (n && (!xyz || !out))) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_sample_world: missing argument");
    return guarded(err, v->path.c_str(), [&] {
        const FloatGrid& grid = *v->grid;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, SAMPLE_GRAIN), [&](const tbb::blocked_range<size_t>& r) {
            FloatGrid::ConstAccessor acc = grid.getConstAccessor(); // one per task: accessors cache, so are not shared
            openvdb::tools::GridSampler<FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> s(acc, grid.transform());
            for (size_t i = r.begin(); i != r.end(); ++i)
                out[i] = s.wsSample(openvdb::Vec3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
        });
    });
}

veil_result veil_vdb_dense(const veil_vdb* v, const int lo[3], const int hi[3], float* out)
{
    if (!v || !lo || !hi || !out) return VEIL_ERR_INVALID;
    size_t d[3];
    for (int a = 0; a < 3; ++a) {
        if (hi[a] < lo[a]) return VEIL_ERR_INVALID;
        d[a] = (size_t)((long long)hi[a] - lo[a] + 1);
    }
    size_t total;
    if (!veil_mul_sizes(d[0], d[1], d[2], sizeof(float), &total)) return VEIL_ERR_LIMIT;
    return guarded(nullptr, v->path.c_str(), [&] {
        FloatGrid::ConstAccessor acc = v->grid->getConstAccessor();
        size_t i = 0;
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) out[i++] = acc.getValue(Coord(x, y, z));
    });
}

veil_result veil_vdb_each_voxel(const veil_vdb* v, veil_vdb_voxel_fn fn, void* user, veil_error* err)
{
    if (!v || !fn) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_each_voxel: missing argument");
    return guarded(err, v->path.c_str(), [&] {
        for (auto it = v->grid->cbeginValueOn(); it; ++it) {
            float value = *it;
            if (value == 0.0f) continue;
            CoordBBox box;
            it.getBoundingBox(box); // one voxel, or an active tile's voxels
            for (int z = box.min()[2]; z <= box.max()[2]; ++z)
                for (int y = box.min()[1]; y <= box.max()[1]; ++y)
                    for (int x = box.min()[0]; x <= box.max()[0]; ++x) {
                        const int ijk[3] = {x, y, z};
                        fn(user, ijk, value);
                    }
        }
    });
}

veil_result veil_vdb_each_box(const veil_vdb* v, veil_vdb_box_fn fn, void* user, veil_error* err)
{
    if (!v || !fn) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_each_box: missing argument");
    return guarded(err, v->path.c_str(), [&] {
        const FloatGrid::TreeType& tree = v->grid->tree();
        for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
            CoordBBox box;
            uint64_t n = 0;
            for (auto it = leaf->cbeginValueOn(); it; ++it)
                if (*it != 0.0f) box.expand(it.getCoord()), ++n;
            if (!n) continue;
            const int lo[3] = {box.min()[0], box.min()[1], box.min()[2]}, hi[3] = {box.max()[0], box.max()[1], box.max()[2]};
            if (!fn(user, lo, hi, n, 0)) return;
        }
        // the tiles: every level above the leaves (their values are the tiles')
        FloatGrid::ValueOnCIter it = v->grid->cbeginValueOn();
        it.setMaxDepth(FloatGrid::ValueOnCIter::LEAF_DEPTH - 1);
        for (; it; ++it) {
            if (*it == 0.0f) continue;
            CoordBBox box;
            it.getBoundingBox(box);
            const int lo[3] = {box.min()[0], box.min()[1], box.min()[2]}, hi[3] = {box.max()[0], box.max()[1], box.max()[2]};
            if (!fn(user, lo, hi, box.volume(), 1)) return;
        }
    });
}

static int census_box(void* user, const int lo[3], const int hi[3], uint64_t voxels, int tile)
{
    (void)lo, (void)hi;
    veil_vdb_census* c = static_cast<veil_vdb_census*>(user);
    if (tile) ++c->tiles, c->tile_voxels += (double)voxels;
    else ++c->leaves, c->leaf_voxels += voxels;
    return 1;
}

veil_result veil_vdb_census_of(const veil_vdb* v, veil_vdb_census* out, veil_error* err)
{
    if (!out) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_census_of: missing argument");
    *out = veil_vdb_census{};
    return veil_vdb_each_box(v, census_box, out, err);
}

veil_result veil_vdb_file_info(const char* path, veil_vdb_grid_info** grids, size_t* count, veil_error* err)
{
    if (!path || !grids || !count) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_file_info: missing argument");
    *grids = nullptr;
    *count = 0;
    veil_vdb_grid_info* out = nullptr;
    size_t n = 0;
    veil_result r = guarded(err, path, [&] {
        read_budget budget(path);
        const bool nano = is_nanovdb(path);
        openvdb::io::File file(path);
        openvdb::GridPtrVec metas = file_grids(file, path, nano);
        out = static_cast<veil_vdb_grid_info*>(std::calloc(metas.size() ? metas.size() : 1, sizeof *out));
        if (!out) throw std::bad_alloc();
        for (const auto& m : metas) fill_info(path, nano ? nullptr : &file, *m, out[n++]);
        if (!nano) file.close();
    });
    if (r != VEIL_OK) {
        veil_vdb_file_info_free(out, n);
        return r;
    }
    *grids = out;
    *count = n;
    return VEIL_OK;
}

void veil_vdb_file_info_free(veil_vdb_grid_info* grids, size_t count)
{
    if (!grids) return;
    for (size_t i = 0; i < count; ++i) std::free(grids[i].name);
    std::free(grids);
}

veil_result veil_vdb_info_json(const char* path, char** json_out, veil_error* err)
{
    if (!json_out) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_info_json: json_out is required");
    *json_out = nullptr;
    veil_vdb_grid_info* grids = nullptr;
    size_t n = 0;
    veil_result r = veil_vdb_file_info(path, &grids, &n, err);
    if (r != VEIL_OK) return r;
    cJSON* root = cJSON_CreateObject();
    cJSON* arr = cJSON_CreateArray();
    if (root && arr) {
        add_text(root, "file", path);
        cJSON_AddItemToObject(root, "grids", arr);
        arr = nullptr;
        for (size_t i = 0; i < n; ++i) cJSON_AddItemToArray(cJSON_GetObjectItem(root, "grids"), grid_json(grids[i]));
        *json_out = cJSON_Print(root);
    }
    cJSON_Delete(arr);
    cJSON_Delete(root);
    veil_vdb_file_info_free(grids, n);
    if (!*json_out) return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory while writing the grid summary", path);
    return VEIL_OK;
}


veil_result veil_vdb_from_dense(const char* label, const char* name, const float* data, const int dims[3],
                                int z_fastest, const double index_to_world[4][4], veil_vdb** out, veil_error* err)
{
    if (out) *out = nullptr;
    if (!label || !name || !data || !dims || !index_to_world || !out)
        return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_from_dense: missing argument");
    for (int a = 0; a < 3; ++a)
        if (dims[a] < 1) return veil_fail(err, VEIL_ERR_INVALID, "%s: dimension %d is %d (at least 1)", label, a, dims[a]);
    veil_vdb* v = nullptr;
    return guarded(err, label, [&] {
        init_openvdb();
        const CoordBBox box(Coord(0, 0, 0), Coord(dims[0] - 1, dims[1] - 1, dims[2] - 1));
        FloatGrid::Ptr grid = FloatGrid::create(0.0f);
        float* values = const_cast<float*>(data); // Dense wants a mutable pointer; copyFromDense only reads it
        if (z_fastest) {
            openvdb::tools::Dense<float, openvdb::tools::LayoutZYX> dense(box, values);
            openvdb::tools::copyFromDense(dense, *grid, 0.0f);
        } else {
            openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, values);
            openvdb::tools::copyFromDense(dense, *grid, 0.0f);
        }
        grid->setName(name);
        grid->setGridClass(openvdb::GRID_FOG_VOLUME);
        place(*grid, index_to_world, label);
        const std::string where = std::string(label) + ": grid " + quoted(name);
        const veil_vdb_values values_range = scan_values(*grid, where);
        v = new veil_vdb{label, name, grid, grid->evalActiveVoxelBoundingBox(), grid->activeVoxelCount(), "",
                         values_range};
        *out = v;
    });
}

veil_result veil_vdb_place(veil_vdb* v, const double m[4][4], veil_error* err)
{
    if (!v || !m) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_place: missing argument");
    return guarded(err, v->path.c_str(), [&] {
        const openvdb::math::Transform& t = v->grid->transform();
        if (!t.baseMap()->isLinear())
            fail_with(VEIL_ERR_INVALID, v->path + ": grid " + ("'" + v->name + "'") + " has a non-affine transform (" +
                                            t.baseMap()->type() + "); a source's \"transform\" needs an affine one");
        double own[4][4], c[4][4];
        to_column_matrix(t, own);
        for (int r = 0; r < 4; ++r)
            for (int k = 0; k < 4; ++k) {
                double s = 0.0;
                for (int j = 0; j < 4; ++j) s += m[r][j] * own[j][k];
                c[r][k] = s;
            }
        place(*v->grid, c, v->path.c_str());
    });
}

veil_result veil_vdb_velocity_open(const char* path, const char* grid_name, veil_vdb_velocity** out, char* chosen,
                                   size_t chosen_len, veil_error* err)
{
    if (out) *out = nullptr;
    if (!path || !out) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_velocity_open: path and out are required");
    veil_vdb_velocity* v = nullptr;
    veil_result r = guarded(err, path, [&] {
        read_budget budget(path);
        const bool nano = is_nanovdb(path);
        openvdb::io::File file(path);
        openvdb::GridPtrVec metas = file_grids(file, path, nano);
        static const char* const names[] = VEIL_VDB_VELOCITY_NAMES;
        std::string name, triple[3];
        GridBase::Ptr meta;
        if (grid_name) {
            name = grid_name;
            meta = velocity_candidate(metas, name, triple);
            if (!meta && triple[0].empty()) {
                GridBase::Ptr g = find_grid(metas, name);
                if (!g)
                    fail_with(VEIL_ERR_INVALID, std::string(path) + ": no velocity grid named " + quoted(name) +
                                                    " (a vec3 grid, or three float grids " + quoted(name + ".x") +
                                                    ", .y, .z); the file has " + list_grids(metas));
                fail_with(VEIL_ERR_INVALID, std::string(path) + ": grid " + quoted(name) + " has value type " +
                                                g->valueType() + ", not a vector: a velocity is a vec3s or vec3d grid, "
                                                "or three float grids " + quoted(name + ".x") + ", .y, .z");
            }
        } else {
            for (const char* n : names) {
                name = n;
                meta = velocity_candidate(metas, name, triple);
                if (meta || !triple[0].empty()) break;
            }
            if (!meta && triple[0].empty())
                fail_with(VEIL_ERR_INVALID, std::string(path) + ": no velocity grid: looked for 'vel', 'v' and "
                                                "'velocity' (a vec3 grid, or three float grids NAME.x, .y, .z); the "
                                                "file has " + list_grids(metas) + "; name one with velocity.grid");
        }
        std::unique_ptr<veil_vdb_velocity> vel(new veil_vdb_velocity);
        vel->path = path;
        if (meta) {
            vel->name = name;
            if (!nano) check_tree(path, name);
            GridBase::Ptr g = nano ? meta : file.readGrid(name);
            vel->staggered = g->getGridClass() == openvdb::GRID_STAGGERED;
            vel->grid = as_vec3s(g);
        } else {
            vel->name = name + ".x/.y/.z";
            FloatGrid::Ptr c[3];
            for (int a = 0; a < 3; ++a) {
                if (!nano) check_tree(path, triple[a]);
                c[a] = openvdb::gridPtrCast<FloatGrid>(nano ? find_grid(metas, triple[a]) : file.readGrid(triple[a]));
                if (!c[a]) fail_with(VEIL_ERR_IO, std::string(path) + ": grid " + quoted(triple[a]) + ": OpenVDB "
                                                                         "returned no float grid");
            }
            vel->grid = merge_triple(c, std::string(path) + ": velocity " + quoted(vel->name));
        }
        if (!nano) file.close();
        if (!vel->grid->transform().baseMap()->isLinear())
            fail_with(VEIL_ERR_INVALID, std::string(path) + ": grid " + quoted(vel->name) +
                                            " has a non-affine transform (" + vel->grid->transform().baseMap()->type() +
                                            "); veil reads velocity grids whose index-to-world map is affine");
        zero_inactive(*vel->grid);
        scan_velocity(*vel);
        v = vel.release();
    });
    if (r != VEIL_OK) return r;
    copy_name(v->name, chosen, chosen_len);
    *out = v;
    return VEIL_OK;
}

void veil_vdb_velocity_close(veil_vdb_velocity* v) { delete v; }

double veil_vdb_velocity_max(const veil_vdb_velocity* v) { return v ? v->max : 0.0; }

veil_result veil_vdb_velocity_place(veil_vdb_velocity* v, const double m[4][4], veil_error* err)
{
    if (!v || !m) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_velocity_place: missing argument");
    return guarded(err, v->path.c_str(), [&] {
        double own[4][4], c[4][4], lin[3][3];
        to_column_matrix(v->grid->transform(), own);
        for (int r = 0; r < 4; ++r)
            for (int k = 0; k < 4; ++k) {
                double s = 0.0;
                for (int j = 0; j < 4; ++j) s += m[r][j] * own[j][k];
                c[r][k] = s;
            }
        place(*v->grid, c, v->path.c_str());
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) lin[r][k] = m[r][0] * v->lin[0][k] + m[r][1] * v->lin[1][k] + m[r][2] * v->lin[2][k];
        std::memcpy(v->lin, lin, sizeof lin);
        scan_velocity(*v);
    });
}

veil_result veil_vdb_advect_work_of(const veil_vdb* g, const veil_vdb_velocity* vel, const veil_vdb_advect_desc* d,
                                    veil_vdb_advect_work* out, veil_error* err)
{
    if (!g || !vel || !d || !out) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_advect_work_of: missing argument");
    *out = veil_vdb_advect_work{};
    if (const char* bad = bad_advect_desc(d))
        return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_advect_work_of: %s", bad);
    return guarded(err, g->path.c_str(), [&] {
        const advect_plan p = plan_paths(*g, *vel, *d, g->path + ": grid " + quoted(g->name));
        out->reach = p.reach;
        out->max_displacement_voxels = p.displacement;
        if (p.reach == 0 || g->active == 0) return; // nothing moves: no work
        count_grown(*g->grid, p.reach, 2.0 * (double)VEIL_VDB_ADVECT_MAX_VOXELS, out->voxels, out->at_least);
        out->reads_per_voxel = p.reads_per_voxel;
        out->reads = out->voxels * p.reads_per_voxel;
    });
}

veil_result veil_vdb_advect_mean(veil_vdb* g, const veil_vdb_velocity* vel, const veil_vdb_advect_desc* d,
                                 veil_vdb_advect_report* report, veil_error* err)
{
    if (!g || !vel || !d) return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_advect_mean: missing argument");
    if (const char* bad = bad_advect_desc(d))
        return veil_fail(err, VEIL_ERR_INVALID, "veil_vdb_advect_mean: %s (n %d, scale %g, step %g)", bad, d->n,
                         d->scale, d->max_step_voxels);
    veil_vdb_advect_report rep{};
    rep.voxels_in = rep.voxels_out = g->active;
    veil_result r = guarded(err, g->path.c_str(), [&] {
        const std::string where = g->path + ": grid " + quoted(g->name);
        const advect_plan p = plan_paths(*g, *vel, *d, where);
        rep.max_displacement_voxels = p.displacement;
        if (p.reach == 0 || g->active == 0) return; // nothing moves: g as it is
        rep.reach = p.reach;
        const openvdb::math::Transform& xf = g->grid->transform();
        // counted on a coarse mask before the region is made: grown voxel by voxel, a region over the
        // limit costs its border's leaves first (a reach of 4 000 voxels: 6 GB)
        double estimate = 0.0;
        int at_least = 0;
        count_grown(*g->grid, p.reach, 2.0 * (double)VEIL_VDB_ADVECT_MAX_VOXELS, estimate, at_least);
        if (estimate > (double)VEIL_VDB_ADVECT_MAX_VOXELS)
            fail_with(VEIL_ERR_LIMIT, where + ": motion blur over its active region grown by " +
                                          std::to_string(p.reach) + " voxels (the largest displacement) covers " +
                                          (at_least ? "over " : "about ") + number_text(estimate) +
                                          " voxels, over the limit of " + std::to_string(VEIL_VDB_ADVECT_MAX_VOXELS) +
                                          ": shorten the shutter or lower the velocity's scale");
        FloatGrid::ConstPtr src = d->clamp_negative ? clamped(*g) : FloatGrid::ConstPtr(g->grid);
        FloatGrid::Ptr out = grown_topology(*src, p.reach);
        const openvdb::Index64 voxels = out->activeVoxelCount();
        if (voxels > VEIL_VDB_ADVECT_MAX_VOXELS)
            fail_with(VEIL_ERR_LIMIT, where + ": motion blur over its active region grown by " +
                                          std::to_string(p.reach) + " voxels (the largest displacement) covers " +
                                          std::to_string(voxels) + " voxels, over the limit of " +
                                          std::to_string(VEIL_VDB_ADVECT_MAX_VOXELS) +
                                          ": shorten the shutter or lower the velocity's scale");
        out->tree().voxelizeActiveTiles();
        rep.reads = (double)voxels * p.reads_per_voxel;

        // k: a raw vector v moves an index point by k v per unit of time: (M^-1 lin) scale, M g's 3x3
        openvdb::Mat3d mc, lc;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) mc(i, j) = p.m[i][j], lc(i, j) = vel->lin[i][j];
        const openvdb::Mat3d kc = mc.inverse() * lc;
        const bool same = vel->grid->transform() == xf;
        const double inv_n = 1.0 / d->n;

        openvdb::tree::LeafManager<FloatGrid::TreeType> leaves(out->tree());
        auto blur_leaf = [&](FloatGrid::TreeType::LeafNodeType& leaf, FloatGrid::ConstAccessor& sacc,
                             velocity_at& v_at) {
            for (auto it = leaf.beginValueOn(); it; ++it) {
                const Coord c = it.getCoord();
                const openvdb::Vec3d x(c.x(), c.y(), c.z()), vx = v_at(x); // both sides start at x
                double sum = 0.0;
                for (const std::vector<double>* side : {&p.pos, &p.neg}) {
                    // backwards along v for h > 0: the first step a midpoint (RK2) one, the next ones
                    // two-step Adams-Bashforth for steps h after h_prev (second order as well, one
                    // velocity read a step): y -= h ((1 + q/2) v(y) - (q/2) v(y_prev)), q = h / h_prev
                    openvdb::Vec3d y = x, v_prev = vx;
                    double t = 0.0, h_prev = 0.0;
                    for (double tk : *side) {
                        const double span = tk - t;
                        const double steps = std::max(1.0, std::ceil(std::fabs(span) / p.step_time));
                        const double h = span / steps;
                        for (double s = 0; s < steps && h != 0.0; ++s) {
                            if (h_prev == 0.0) {
                                y -= h * v_at(y - 0.5 * h * vx);
                            } else {
                                const openvdb::Vec3d vy = v_at(y);
                                const double q = h / h_prev;
                                y -= h * ((1.0 + 0.5 * q) * vy - (0.5 * q) * v_prev);
                                v_prev = vy;
                            }
                            h_prev = h;
                        }
                        t = tk;
                        sum += openvdb::tools::BoxSampler::sample(sacc, y);
                    }
                }
                const float mean = (float)(sum * inv_n);
                it.setValue(mean);
                if (mean == 0.0f) it.setValueOff();
            }
        };
        // in parts of about VEIL_VDB_ADVECT_PART_READS reads, each in parallel (TBB, one accessor per task:
        // accessors cache), the progress reported and a cancel honoured between them
        const size_t n_leaves = leaves.leafCount();
        const double leaf_reads = (double)FloatGrid::TreeType::LeafNodeType::SIZE * p.reads_per_voxel;
        const size_t part = (size_t)std::max(1.0, std::floor(VEIL_VDB_ADVECT_PART_READS / leaf_reads));
        for (size_t first = 0; first < n_leaves; first += part) {
            if (veil_progress_cancelled())
                fail_with(VEIL_ERR_CANCELLED, where + ": motion blur cancelled");
            veil_progress("motion blur", (double)first, (double)n_leaves);
            const size_t last = std::min(n_leaves, first + part);
            tbb::parallel_for(tbb::blocked_range<size_t>(first, last), [&](const tbb::blocked_range<size_t>& range) {
                FloatGrid::ConstAccessor sacc = src->getConstAccessor();
                velocity_at v_at{*vel, xf, same, {}, vel->grid->getConstAccessor()};
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j) v_at.k[i][j] = kc(i, j) * d->scale;
                for (size_t i = range.begin(); i != range.end(); ++i) blur_leaf(leaves.leaf(i), sacc, v_at);
            });
        }
        if (veil_progress_cancelled()) fail_with(VEIL_ERR_CANCELLED, where + ": motion blur cancelled");
        veil_progress("motion blur", (double)n_leaves, (double)n_leaves);
        openvdb::tools::pruneInactive(out->tree());
        out->setName(g->name);
        out->setGridClass(openvdb::GRID_FOG_VOLUME);
        const veil_vdb_values values = scan_values(*out, where);
        g->grid = out;
        g->active_box = out->evalActiveVoxelBoundingBox();
        g->active = out->activeVoxelCount();
        g->values = values;
        rep.voxels_out = g->active;
    });
    if (report) *report = rep;
    return r;
}

} // extern "C"
