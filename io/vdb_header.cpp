// veil — an OpenVDB file's own claims, checked before OpenVDB reads it
// (io/vdb_header.hpp).
#include "vdb_header.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace {

// What a file's bytes claim, checked against its size before OpenVDB reads
// it: OpenVDB takes lengths and counts from the stream as they come, so a
// truncated or corrupt header made it allocate gigabytes (a 256-byte
// truncation of a 2.5 MB file: 7.6 GB and over 20 s) before failing. The
// layout walked here (little-endian, file versions 218 and later):
//   int64 magic 0x56444220; uint32 file version; uint32 library major and
//   minor; char "has grid offsets"; (versions 220-221: char compression);
//   36 chars UUID; the file's metadata: uint32 count, then per entry a
//   name and a type (uint32 length + chars each) and a value (uint32 size +
//   bytes); then, with grid offsets, int32 grid count and per grid its
//   unique name, type and (216+) instance parent (strings), and int64 grid,
//   block and end positions, the next descriptor at the end position; each
//   grid's own header (grid_header below) within its grid..block bytes.
// Every length, count and position must fit in what is left of the file.
class header_check {
public:
    header_check(const std::string& path) : in_(path, std::ios::binary)
    {
        in_.seekg(0, std::ios::end);
        size_ = (uint64_t)std::max<std::streamoff>(0, (std::streamoff)in_.tellg());
        in_.seekg(0);
    }
    void run()
    {
        if (size_ < 8 || u64() != 0x56444220ull) return; // not an OpenVDB file: OpenVDB says so itself
        uint32_t version = u32();
        if (version < 218) return; // older layouts: left to OpenVDB
        skip(8, "the library version");
        bool offsets = bytes(1, "the grid-offsets flag")[0] != 0;
        if (version < 222) skip(1, "the compression flag");
        skip(36, "the UUID");
        metadata("the file's");
        if (!offsets) return;
        int32_t grids = (int32_t)u32();
        if (grids < 0 || (uint64_t)grids * 36 > left()) bad("the grid count", (uint64_t)(uint32_t)grids);
        for (int32_t i = 0; i < grids; ++i) {
            string("a grid name");
            string("a grid type");
            if (version >= 216) string("a grid's instance parent");
            uint64_t grid = u64(), block = u64(), end = u64();
            if (!(at_ <= grid && grid <= block && block <= end && end <= size_)) {
                char what[200];
                std::snprintf(what, sizeof what, "grid %d's data at bytes %llu..%llu", (int)i, (unsigned long long)grid,
                              (unsigned long long)end);
                bad(what, end);
            }
            grid_header(version, grid, block);
            in_.clear();
            in_.seekg((std::streamoff)end);
            at_ = end;
        }
    }

private:
    // A metadata block as OpenVDB's MetaMap reads it: uint32 count, then per
    // entry a name, a type and uint32 size + value. OpenVDB reads a value of
    // a fixed-size type (int32, vec3i, mat4d, ...) by the type's size, not by
    // the stored one, so the two must agree or the reading goes astray (and
    // takes later bytes for string lengths); a "__delayedload" value starts
    // with a count of entries of at least a byte each, which sizes vectors.
    void metadata(const char* whose)
    {
        static const std::pair<const char*, uint32_t> fixed[] = {
            {"bool", 1},   {"int32", 4},  {"int64", 8},   {"float", 4},  {"double", 8}, {"vec2i", 8},
            {"vec2s", 8},  {"vec2d", 16}, {"vec3i", 12},  {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16},
            {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64},  {"mat4d", 128}};
        std::string what = std::string(whose) + " metadata";
        uint32_t entries = u32();
        if ((uint64_t)entries * 12 > left()) bad((what + " count").c_str(), entries);
        for (uint32_t e = 0; e < entries; ++e) {
            string((what + " name").c_str());
            uint32_t type_len = u32();
            std::string type(bytes(type_len, (what + " type").c_str()), type_len);
            uint32_t value = u32();
            if (value > left()) bad((what + " value").c_str(), value);
            for (const auto& f : fixed)
                if (type == f.first && value != f.second) {
                    char msg[300];
                    std::snprintf(msg, sizeof msg, "corrupt OpenVDB file: %s value of type %s has %u bytes where the "
                                  "type has %u (at byte %llu)", what.c_str(), type.c_str(), value, f.second,
                                  (unsigned long long)at_);
                    throw std::string(msg);
                }
            if (type == "__delayedload" && value >= 4) {
                uint32_t count = u32();
                if ((uint64_t)count + 4 > value) bad("a delayed-load count", count);
                skip(value - 4, what.c_str());
            } else {
                skip(value, what.c_str());
            }
        }
    }

    // A grid's own header, bytes [grid, block): (222+) uint32 compression, its
    // metadata, then the transform's type name.
    void grid_header(uint32_t version, uint64_t grid, uint64_t block)
    {
        uint64_t saved = size_;
        in_.clear();
        in_.seekg((std::streamoff)grid);
        at_ = grid;
        size_ = block; // nothing of the header may reach past its block
        if (version >= 222) skip(4, "a grid's compression flags");
        metadata("a grid's");
        string("a grid's transform type");
        size_ = saved;
    }

    [[noreturn]] void bad(const char* what, uint64_t value)
    {
        char msg[400];
        std::snprintf(msg, sizeof msg, "truncated or corrupt OpenVDB file: %s (%llu) does not fit in its %llu bytes "
                      "(at byte %llu)", what, (unsigned long long)value, (unsigned long long)size_,
                      (unsigned long long)at_);
        throw std::string(msg);
    }
    uint64_t left() const { return size_ - at_; }
    const char* bytes(uint64_t n, const char* what)
    {
        if (n > left()) bad(what, n);
        buf_.resize((size_t)n);
        if (n && !in_.read(buf_.data(), (std::streamsize)n)) bad(what, n);
        at_ += n;
        return buf_.data();
    }
    void skip(uint64_t n, const char* what)
    {
        if (n > left()) bad(what, n);
        in_.seekg((std::streamoff)n, std::ios::cur);
        at_ += n;
    }
    uint32_t u32()
    {
        const unsigned char* b = (const unsigned char*)bytes(4, "a count");
        return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    }
    uint64_t u64()
    {
        uint64_t lo = u32();
        return lo | (uint64_t)u32() << 32;
    }
    void string(const char* what) { skip(u32(), what); }

    std::ifstream in_;
    uint64_t size_ = 0, at_ = 0;
    std::vector<char> buf_;
};

} // namespace

bool veil__vdb_header_ok(const std::string& path, std::string* why)
{
    try {
        header_check(path).run();
        return true;
    } catch (const std::string& msg) {
        *why = msg;
        return false;
    }
}
