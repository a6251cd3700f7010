// veil — an OpenVDB file's own claims, checked before OpenVDB reads it
// (io/vdb_header.hpp).
#include <string>
#pragma GCC visibility push(hidden) // veil's own, not part of libveil.so's ABI (io/vdb.cpp says why a pragma)
#include "vdb_header.hpp"
#pragma GCC visibility pop

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace {

// What a file's bytes claim, checked against its size before OpenVDB reads
// it: OpenVDB takes lengths and counts from the stream as they come, so a
// truncated or corrupt header made it allocate gigabytes (a 256-byte
// truncation of a 2.5 MB file: 7.6 GB and over 20 s) before failing. The
// layout walked here (little-endian, file versions 222 and later):
//   int64 magic 0x56444220; uint32 file version; uint32 library major and
//   minor; char "has grid offsets" (1: the files io::File writes; 0, a
//   stream's, is refused); 36 chars UUID; the file's metadata:
//   uint32 count, then per entry a name and a type (uint32 length + chars
//   each) and a value (uint32 size + bytes); then, with grid offsets, int32
//   grid count and per grid its unique name, type and instance parent
//   (strings), and int64 grid, block and end positions, the next descriptor
//   at the end position. A grid's bytes [grid, block) are its header
//   (grid_header below), [block, end) its tree (tree below).
// Every length, count and position must fit in what is left of the file.
class walk {
public:
    explicit walk(const std::string& path)
    {
        fd_ = open(path.c_str(), O_RDONLY | O_CLOEXEC);
        struct stat st;
        if (fd_ >= 0 && fstat(fd_, &st) == 0) size_ = (uint64_t)st.st_size;
    }
    ~walk()
    {
        if (fd_ >= 0) close(fd_);
    }
    walk(const walk&) = delete;
    walk& operator=(const walk&) = delete;

    // false: not an OpenVDB file (OpenVDB says so itself)
    bool header()
    {
        if (fd_ < 0 || size_ < 8 || u64() != 0x56444220ull) return false;
        version_ = u32();
        if (version_ < 222) {
            char msg[300];
            std::snprintf(msg, sizeof msg, "OpenVDB file version %u, older than 222 (OpenVDB 2.0, 2013): veil reads "
                          "version 222 and later; write it again with a current OpenVDB", version_);
            throw std::string(msg);
        }
        skip(8, "the library version");
        bool offsets = bytes(1, "the grid-offsets flag")[0] != 0;
        skip(36, "the UUID");
        metadata("the file's", size_);
        if (!offsets) // OpenVDB's io::Stream writes these; io::File then reads every grid whole, unchecked
            throw std::string("an OpenVDB file without grid offsets (written by a stream, not io::File): veil reads "
                              "files with them; write it again with a current OpenVDB (vdb_tool -read -write)");
        int32_t count = (int32_t)u32();
        if (count < 0 || (uint64_t)count * 36 > left()) bad("the grid count", (uint64_t)(uint32_t)count);
        for (int32_t i = 0; i < count; ++i) {
            grid g;
            g.name = string("a grid name");
            g.type = string("a grid type");
            g.parent = string("a grid's instance parent");
            g.grid = u64();
            g.block = u64();
            g.end = u64();
            if (!g.parent.empty()) g.block = g.end; // an instance has no tree (OpenVDB writes block 0)
            if (!(at_ <= g.grid && g.grid <= g.block && g.block <= g.end && g.end <= size_)) {
                char what[200];
                std::snprintf(what, sizeof what, "grid %d's data at bytes %llu..%llu", (int)i,
                              (unsigned long long)g.grid, (unsigned long long)g.end);
                bad(what, g.end);
            }
            grid_header(g);
            grids_.push_back(g);
            at_ = g.end;
        }
        return true;
    }

    // Walks the tree of every grid whose name (the unique name up to
    // OpenVDB's suffix separator, ASCII 0x1e) is `name`, and of the grids
    // they are instances of; of every grid when there is none, or an
    // instance's parent is not found (OpenVDB's lookup may differ).
    void trees(const std::string& name)
    {
        std::vector<char> want(grids_.size(), 0); // each grid once, whatever the names repeat
        std::vector<size_t> todo;
        std::unordered_map<std::string, std::vector<size_t>> by_name; // unique name -> grids (made when needed)
        for (size_t i = 0; i < grids_.size(); ++i)
            if (grids_[i].name.substr(0, grids_[i].name.find('\x1e')) == name) want[i] = 1, todo.push_back(i);
        bool all = todo.empty(); // OpenVDB may find what this does not: then every tree is walked
        for (size_t k = 0; k < todo.size() && !all; ++k) {
            const grid& g = grids_[todo[k]];
            if (g.parent.empty()) continue;
            if (by_name.empty())
                for (size_t i = 0; i < grids_.size(); ++i) by_name[grids_[i].name].push_back(i);
            auto p = by_name.find(g.parent);
            all = p == by_name.end();
            if (!all)
                for (size_t i : p->second)
                    if (!want[i]) want[i] = 1, todo.push_back(i);
        }
        for (size_t i = 0; i < grids_.size(); ++i)
            if (grids_[i].parent.empty() && (all || want[i])) tree(grids_[i]);
    }

private:
    struct grid {
        std::string name, type, parent;
        uint64_t grid = 0, topology = 0, block = 0, end = 0;
        uint32_t compression = 0;
        int half = -1; // its is_saved_as_half_float metadata: -1 none, 0 or 1 a bool's value, 2 another type
    };

    // OpenVDB's compression flags (io/Compression.h) and the metadata byte
    // before each node's values: 0..6, of which 2, 4 and 5 store one
    // inactive value (5: two) and 3, 4 and 5 a selection mask; 6 stores
    // every value (no mask compression).
    enum { ZIP = 1, ACTIVE_MASK = 2, BLOSC = 4 };

    // A metadata block as OpenVDB's MetaMap reads it: uint32 count, then per
    // entry a name, a type and uint32 size + value. OpenVDB reads a value of
    // a fixed-size type (int32, vec3i, mat4d, ...) by the type's size, not by
    // the stored one, so the two must agree or the reading goes astray (and
    // takes later bytes for string lengths); a "__delayedload" value is
    // checked as delayed_load() says. `span`: the bytes of the grid (the
    // file's, for the file's metadata).
    void metadata(const char* whose, uint64_t span, int* half = nullptr)
    {
        static const std::pair<const char*, uint32_t> fixed[] = {
            {"bool", 1},   {"int32", 4},  {"int64", 8},   {"float", 4},  {"double", 8}, {"vec2i", 8},
            {"vec2s", 8},  {"vec2d", 16}, {"vec3i", 12},  {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16},
            {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64},  {"mat4d", 128}};
        std::string what = std::string(whose) + " metadata";
        uint32_t entries = u32();
        if ((uint64_t)entries * 12 > left()) bad((what + " count").c_str(), entries);
        for (uint32_t e = 0; e < entries; ++e) {
            const std::string name = string((what + " name").c_str());
            std::string type = string((what + " type").c_str());
            uint32_t value = u32();
            if (value > left()) bad((what + " value").c_str(), value);
            const bool half_entry = half && name == "is_saved_as_half_float"; // see tree()
            for (const auto& f : fixed)
                if (type == f.first && value != f.second) {
                    char msg[300];
                    std::snprintf(msg, sizeof msg, "corrupt OpenVDB file: %s value of type %s has %u bytes where the "
                                  "type has %u (at byte %llu)", what.c_str(), type.c_str(), value, f.second,
                                  (unsigned long long)at_);
                    throw std::string(msg);
                }
            if (half_entry) *half = 2;
            if (half_entry && type == "bool") { // its one byte (checked above)
                *half = bytes(1, "a bool")[0] != 0;
            } else if (type == "__delayedload" && value > 0) {
                delayed_load(value, span);
            } else {
                skip(value, what.c_str());
            }
        }
    }

    // A "__delayedload" value (OpenVDB's DelayedLoadMetadata, written with
    // each grid): uint32 count (one entry a leaf); a mask array of count
    // bytes and a size array of count int64, each as uint32 n then n bytes
    // of blosc (n 0: the raw array; for the sizes, n 0xffffffff: none).
    // OpenVDB sizes its arrays by the count and by the blosc header's claim
    // before reading; a leaf takes at least 128 bytes of the grid (its mask
    // twice), which bounds the count, and a blosc chunk must claim the
    // array's size in its own (128 for an array under 128 bytes: OpenVDB
    // pads those before compressing).
    void delayed_load(uint32_t value, uint64_t span)
    {
        const uint64_t end = at_ + value;
        if (value < 12) bad("a delayed-load value", value);
        const uint32_t count = u32();
        if ((uint64_t)count * 128 > span) bad("a delayed-load count (its leaves' bytes)", (uint64_t)count * 128);
        for (int a = 0; a < 2; ++a) {
            if (end - at_ < 4) bad("a delayed-load value", value);
            const uint32_t n = u32();
            const uint64_t raw = (uint64_t)count * (a ? 8 : 1);
            if (a && n == 0xffffffffu) continue;
            if (n == 0) {
                if (raw > end - at_) bad("a delayed-load array", raw);
                skip(raw, "a delayed-load array");
                continue;
            }
            if (n > end - at_) bad("a delayed-load chunk", n);
            if (n < 16) chunk(n, raw);
            const unsigned char* h = (const unsigned char*)bytes(16, "a blosc header");
            const uint64_t holds = le32(h + 4); // arrays under 128 bytes are padded to 128 before blosc
            if ((holds != raw && !(raw < 128 && holds == 128)) || le32(h + 12) != n) chunk(n, raw, true, holds, le32(h + 12));
            skip(n - 16, "a delayed-load chunk");
        }
        skip(end - at_, "a delayed-load value");
    }

    // A grid's own header, from its grid position: uint32 compression
    // flags, its metadata, then its transform (map()); its tree's topology
    // follows, up to the block position.
    void grid_header(grid& g)
    {
        limit within(*this, g.grid, g.block); // nothing of the header may reach past its block
        g.compression = u32();
        metadata("a grid's", g.end - g.grid, &g.half);
        map(string("a grid's transform type"), true);
        g.topology = at_;
    }

    // A transform's map as OpenVDB's maps read themselves: doubles (an
    // affine or unitary map's 4x4 matrix; a scale map's 5 vec3d, 6 with a
    // translation; a translation), a frustum's box, taper and depth followed
    // by a second map (its type name, then it; not a frustum again: OpenVDB
    // would recurse as deep as the file goes). Another type name is not a
    // map OpenVDB knows; it says so itself when it reads the grid.
    void map(const std::string& type, bool frustum_allowed)
    {
        static const std::pair<const char*, uint32_t> sizes[] = {
            {"AffineMap", 128},          {"UnitaryMap", 128},          {"ScaleMap", 120},
            {"UniformScaleMap", 120},    {"ScaleTranslateMap", 144},   {"UniformScaleTranslateMap", 144},
            {"TranslationMap", 24}};
        for (const auto& m : sizes)
            if (type == m.first) {
                skip(m.second, "a grid's transform");
                return;
            }
        if (type == "NonlinearFrustumMap" && frustum_allowed) {
            skip(48 + 16, "a frustum's box, taper and depth");
            map(string("a frustum's second map type"), false);
            return;
        }
        std::string msg = "corrupt OpenVDB file: a grid's transform has the type '" + type.substr(0, 64) +
                          "', not one of OpenVDB's maps";
        throw msg;
    }

    // A tree (its topology after the grid's header, up to the block
    // position; its buffers from there to the end position), as OpenVDB's Tree, RootNode, InternalNode
    // and LeafNode read it (readTopology, then readBuffers), for the 5-4-3
    // layout: int32 buffer count; the root's background value, uint32 tile
    // and child counts, each tile (int32 x3 origin, value, bool active),
    // each child (int32 x3 origin, then a node of 32³); a node of 32³ or 16³
    // is its child mask and value mask, its values (values() below) and its
    // children in the order of the child mask's set bits; a leaf (8³) is a
    // value mask. Then, leaf by leaf in that order, the leaf's buffer: its
    // value mask again and its values (a bool leaf: the mask, int32 x3
    // origin and a 64-byte mask of values).
    void tree(const grid& g)
    {
        // Stored as half: OpenVDB reads the tree as its metadata says (a
        // bool named is_saved_as_half_float), which the type's suffix
        // repeats; a file where they differ, or where the bool is missing or
        // of another type, is not one the walk can follow as OpenVDB will.
        std::string t = g.type;
        bool half = false;
        const std::string hs = "_HalfFloat";
        if (t.size() > hs.size() && t.compare(t.size() - hs.size(), hs.size(), hs) == 0) {
            half = true;
            t.resize(t.size() - hs.size());
        }
        if (g.half == 2 || (g.half == -1 && half) || (g.half >= 0 && g.half <= 1 && (g.half == 1) != half)) {
            static const char* const says[] = {"false", "true", "of another type than bool"};
            std::string msg = "corrupt OpenVDB file: grid '" + g.name.substr(0, g.name.find('\x1e')) + "' has the "
                              "type " + g.type + " but its metadata is_saved_as_half_float is " +
                              (g.half < 0 ? "missing" : says[g.half]);
            throw msg;
        }
        static const struct {
            const char* type;
            uint32_t size, half; // bytes of a value, and of one stored as half (0: not a real type)
        } types[] = {{"Tree_float_5_4_3", 4, 2},  {"Tree_double_5_4_3", 8, 2}, {"Tree_int32_5_4_3", 4, 0},
                     {"Tree_int64_5_4_3", 8, 0},  {"Tree_vec3s_5_4_3", 12, 6}, {"Tree_vec3d_5_4_3", 24, 6},
                     {"Tree_vec3i_5_4_3", 12, 0}, {"Tree_bool_5_4_3", 1, 0}};
        value_ = 0;
        for (const auto& k : types)
            if (t == k.type) value_ = k.size, stored_ = half && k.half ? k.half : k.size;
        if (!value_) {
            std::string msg = "grid '" + g.name.substr(0, g.name.find('\x1e')) + "' has a tree of type " + g.type +
                              ", which veil does not read (it reads float, double, int32, int64, vec3s, vec3d, vec3i "
                              "and bool grids)";
            throw msg;
        }
        bool_ = t == "Tree_bool_5_4_3";
        compression_ = g.compression;
        leaves_.clear();
        {
            limit within(*this, g.topology, g.block);
            skip(4, "a tree's buffer count");
            skip(value_, "a tree's background");
            uint32_t tiles = u32(), children = u32();
            if ((uint64_t)tiles * (13 + value_) + (uint64_t)children * (12 + 8192) > left())
                bad("a root's tile and child counts", (uint64_t)tiles + children);
            skip((uint64_t)tiles * (13 + value_), "a root's tiles");
            for (uint32_t c = 0; c < children; ++c) {
                skip(12, "a child's origin");
                node(5);
            }
            if (at_ != g.block) {
                char msg[200];
                std::snprintf(msg, sizeof msg, "corrupt OpenVDB file: a tree's topology ends at byte %llu, its buffers "
                              "begin at %llu", (unsigned long long)at_, (unsigned long long)g.block);
                throw std::string(msg);
            }
        }
        limit within(*this, g.block, g.end);
        // OpenVDB counts a leaf's values by one of its two masks (the
        // topology's when it seeks, the buffer's when it reads): their
        // counts must agree (only the count sizes anything; a count a leaf
        // keeps the walk's memory at 2 bytes a leaf of at least 129 in the file)
        for (uint16_t count : leaves_) {
            const uint32_t again = ones((const unsigned char*)bytes(64, "a leaf's value mask"), 64);
            if (again != count) {
                char msg[200];
                std::snprintf(msg, sizeof msg, "corrupt OpenVDB file: a leaf's value mask has %u values on, its "
                              "topology's %u (at byte %llu)", again, (unsigned)count, (unsigned long long)at_);
                throw std::string(msg);
            }
            if (bool_) skip(12 + 64, "a bool leaf's origin and values");
            else values(512, count);
        }
    }

    // A node of (2^log2)³ below the root; log2 3 is a leaf.
    void node(int log2)
    {
        if (log2 == 3) {
            leaves_.push_back((uint16_t)ones((const unsigned char*)bytes(64, "a leaf's value mask"), 64));
            return;
        }
        const uint32_t n = 1u << (3 * log2), mask_bytes = n / 8;
        const char* c = bytes(mask_bytes, "a node's child mask");
        std::vector<unsigned char> children(c, c + mask_bytes);
        const uint32_t active = ones((const unsigned char*)bytes(mask_bytes, "a node's value mask"), mask_bytes);
        values(n, active);
        for (uint32_t b = 0; b < mask_bytes; ++b)
            for (int k = 0; k < 8; ++k)
                if (children[b] >> k & 1) node(log2 == 5 ? 4 : 3);
    }

    // A node's values as io::readCompressedValues reads them, for a node of
    // n values of which `active` are active: (222+) the metadata byte; the
    // inactive values and selection mask it announces; then the values
    // (only the active ones when the grid is mask-compressed and the byte
    // is not 6), as readData reads them: blosc or zip, an int64 size and
    // that many bytes (a size ≤ 0: -size raw bytes, which must be exactly
    // the values' bytes, or OpenVDB reads them into too small a buffer), or
    // the raw values. Values stored as half take half's bytes (and a real
    // type's empty run of halves stores nothing, not even a size). A blosc
    // chunk must carry a header whose sizes agree: blosc trusts them.
    void values(uint32_t n, uint32_t active)
    {
        int meta = (signed char)bytes(1, "a node's compression byte")[0];
        if (meta < 0 || meta > 6) {
            char msg[200];
            std::snprintf(msg, sizeof msg, "corrupt OpenVDB file: a node's compression byte is %d, not 0 to 6 (at "
                          "byte %llu)", meta, (unsigned long long)(at_ - 1));
            throw std::string(msg);
        }
        if (meta == 2 || meta == 4 || meta == 5) skip(value_ * (meta == 5 ? 2 : 1), "a node's inactive values");
        if (meta >= 3 && meta <= 5) skip(n / 8, "a node's selection mask");
        uint64_t count = (compression_ & ACTIVE_MASK) && meta != 6 ? active : n;
        if (count == 0 && stored_ != value_) return;
        uint64_t want = count * stored_;
        if (!(compression_ & (BLOSC | ZIP))) {
            skip(want, "a node's values");
            return;
        }
        int64_t size = (int64_t)u64();
        if (size <= 0) {
            if (size == INT64_MIN || (uint64_t)(-size) != want) chunk(size, want);
            skip(want, "a node's values");
            return;
        }
        if ((uint64_t)size > left()) bad("a compressed chunk", (uint64_t)size);
        if (compression_ & BLOSC) {
            // blosc's 16-byte header: version, format, flags, type size,
            // then uint32 uncompressed, block and compressed sizes
            if (size < 16) chunk(size, want);
            const unsigned char* h = (const unsigned char*)bytes(16, "a blosc header");
            if (le32(h + 4) != want || le32(h + 12) != (uint64_t)size) chunk(size, want, true, le32(h + 4), le32(h + 12));
            skip((uint64_t)size - 16, "a compressed chunk");
        } else {
            skip((uint64_t)size, "a compressed chunk");
        }
    }

    [[noreturn]] void chunk(int64_t size, uint64_t want, bool blosc = false, uint64_t blosc_raw = 0,
                            uint64_t blosc_size = 0)
    {
        char msg[400];
        if (blosc)
            std::snprintf(msg, sizeof msg, "corrupt OpenVDB file: a blosc chunk of %lld bytes says it holds %llu "
                          "bytes in %llu, where the node's values take %llu (at byte %llu)", (long long)size,
                          (unsigned long long)blosc_raw, (unsigned long long)blosc_size, (unsigned long long)want,
                          (unsigned long long)at_);
        else
            std::snprintf(msg, sizeof msg, "corrupt OpenVDB file: a chunk of %lld bytes where the node's values "
                          "take %llu (at byte %llu)", (long long)size, (unsigned long long)want,
                          (unsigned long long)at_);
        throw std::string(msg);
    }

    static uint32_t ones(const unsigned char* b, uint32_t n)
    {
        uint32_t c = 0;
        for (uint32_t i = 0; i < n; ++i) c += (uint32_t)__builtin_popcount(b[i]);
        return c;
    }
    static uint64_t le32(const unsigned char* b)
    {
        return (uint64_t)b[0] | (uint64_t)b[1] << 8 | (uint64_t)b[2] << 16 | (uint64_t)b[3] << 24;
    }

    // Narrows the walk to bytes [from, to) for its lifetime.
    class limit {
    public:
        limit(walk& w, uint64_t from, uint64_t to) : w_(w), saved_(w.size_)
        {
            w.at_ = from;
            w.size_ = to;
        }
        ~limit() { w_.size_ = saved_; }
        limit(const limit&) = delete;
        limit& operator=(const limit&) = delete;

    private:
        walk& w_;
        uint64_t saved_;
    };

    [[noreturn]] void bad(const char* what, uint64_t value)
    {
        char msg[400];
        std::snprintf(msg, sizeof msg, "truncated or corrupt OpenVDB file: %s (%llu) does not fit in its %llu bytes "
                      "(at byte %llu)", what, (unsigned long long)value, (unsigned long long)size_,
                      (unsigned long long)at_);
        throw std::string(msg);
    }
    uint64_t left() const { return size_ > at_ ? size_ - at_ : 0; }

    // The n bytes at the walk's position, through a window of the file read
    // with pread: skipped bytes are never read, a tree's small reads come
    // from one read of the window.
    const char* bytes(uint64_t n, const char* what)
    {
        if (n > left()) bad(what, n);
        if (at_ < win_at_ || at_ + n > win_at_ + win_.size()) {
            const uint64_t want = std::max<uint64_t>(n, std::min<uint64_t>(1u << 16, size_ - at_));
            win_.resize((size_t)want);
            win_at_ = at_;
            uint64_t got = 0;
            while (got < want) {
                ssize_t r = pread(fd_, win_.data() + got, (size_t)(want - got), (off_t)(at_ + got));
                if (r <= 0) {
                    win_.clear();
                    bad(what, n);
                }
                got += (uint64_t)r;
            }
        }
        const char* p = win_.data() + (at_ - win_at_);
        at_ += n;
        return p;
    }
    void skip(uint64_t n, const char* what)
    {
        if (n > left()) bad(what, n);
        at_ += n;
    }
    uint32_t u32() { return (uint32_t)le32((const unsigned char*)bytes(4, "a count")); }
    uint64_t u64()
    {
        uint64_t lo = u32();
        return lo | (uint64_t)u32() << 32;
    }
    std::string string(const char* what)
    {
        uint32_t n = u32();
        return std::string(bytes(n, what), n);
    }

    int fd_ = -1;
    uint64_t size_ = 0, at_ = 0;
    uint32_t version_ = 0;
    std::vector<char> win_;
    uint64_t win_at_ = 0;
    std::vector<grid> grids_;
    // the tree being walked
    uint32_t compression_ = 0, value_ = 0, stored_ = 0;
    bool bool_ = false;
    std::vector<uint16_t> leaves_; // each leaf's active values, in the order of the buffers
};

} // namespace

bool veil__vdb_header_ok(const std::string& path, std::string* why)
{
    try {
        walk(path).header();
        return true;
    } catch (const std::string& msg) {
        *why = msg;
        return false;
    }
}

bool veil__vdb_tree_ok(const std::string& path, const std::string& grid, std::string* why)
{
    try {
        walk w(path);
        if (w.header()) w.trees(grid);
        return true;
    } catch (const std::string& msg) {
        *why = msg;
        return false;
    }
}
