// veil — the deep OpenEXR writer (io/exr_deep.h), in C++ behind a C header.
//
// Why C++: veil writes its flat EXRs through OpenEXRCore, the C API, and
// would write deep ones the same way, but OpenEXRCore 3.1 (Debian 12's
// OpenEXR 3.1.5) cannot encode deep chunks: exr_encoding_run on a deep
// scanline part fails with EXR_ERR_INVALID_ARGUMENT (its default_pack_deep
// is a stub; tried on a 4x3 image of 0-2 samples a pixel). The C++ library
// of the same package (Imf::DeepScanLineOutputFile) writes them, so this
// one file uses it, fenced as io/vdb.cpp fences OpenVDB: one guarded()
// catches every exception and maps it to a result with its message; no C++
// type crosses io/exr_deep.h.
//
// The flat writer (io/exr.c) comes here too for DWAA and DWAB, which
// OpenEXRCore 3.1 cannot encode either (EXR_ERR_FEATURE_NOT_IMPLEMENTED,
// "DWA/A compression not yet implemented in C"): veil__exr_write_imf.
//
// The bytes go through an Imf::OStream over the descriptor of a temporary
// file beside the target (io/tempfile.h), renamed into place only when the
// whole file is written and closed; on failure the temporary is removed and
// an existing target is left as it was.
#include <cerrno>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfDeepFrameBuffer.h>
#include <ImfDeepScanLineOutputFile.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfIntAttribute.h>
#include <ImfFrameBuffer.h>
#include <Imath/half.h>
#include <ImfMatrixAttribute.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <Iex.h>

#pragma GCC visibility push(hidden) // veil's own, not part of libveil.so's ABI (io/vdb.cpp says why a pragma)
#include "exr_deep.h"
extern "C" {
#include "tempfile.h"
}
#pragma GCC visibility pop

namespace {

// An OpenEXR output stream over a file descriptor we own: writes at the
// stream's position (pwrite), so seekp (the chunk table is written last) is
// a position change only.
class fd_ostream : public Imf::OStream {
public:
    fd_ostream(int fd, const char* name) : Imf::OStream(name), fd_(fd) {}
    void write(const char c[], int n) override
    {
        while (n > 0) {
            ssize_t k = pwrite(fd_, c, (size_t)n, (off_t)pos_);
            if (k < 0 && errno == EINTR) continue;
            if (k <= 0) throw Iex::ErrnoExc(std::string("cannot write: ") + std::strerror(k < 0 ? errno : ENOSPC));
            c += k, n -= (int)k, pos_ += (uint64_t)k;
        }
    }
    uint64_t tellp() override { return pos_; }
    void seekp(uint64_t pos) override { pos_ = pos; }

private:
    int fd_;
    uint64_t pos_ = 0;
};

template <typename F>
veil_result guarded(veil_error* err, const char* path, F&& f, const char* what = "the deep OpenEXR file") noexcept
{
    try {
        f();
        return VEIL_OK;
    } catch (const std::bad_alloc&) {
        return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory writing %s", path, what);
    } catch (const std::exception& e) {
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot write %s (OpenEXR said: %s)", path, what, e.what());
    } catch (...) {
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot write %s (unknown C++ exception)", path, what);
    }
}

const char* const k_names[VEIL_DEEP_CHANNELS] = {"R", "G", "B", "A", "Z", "ZBack"};

void add_meta(Imf::Header& h, const veil_exr_meta* m)
{
    if (!m) return;
    if (m->has_frame) h.insert("frame", Imf::IntAttribute(m->frame));
    if (m->has_camera) {
        Imath::M44f wc, wn;
        std::memcpy(&wc[0][0], m->world_to_camera, sizeof(float) * 16);
        std::memcpy(&wn[0][0], m->world_to_ndc, sizeof(float) * 16);
        h.insert("worldToCamera", Imf::M44fAttribute(wc));
        h.insert("worldToNDC", Imf::M44fAttribute(wn));
    }
    for (int i = 0; i < m->n_strings && i < VEIL_EXR_META_STRINGS; ++i)
        if (m->strings[i][0] && m->strings[i][1]) h.insert(m->strings[i][0], Imf::StringAttribute(m->strings[i][1]));
}

void write_file(int fd, const char* path, const veil_deep_image* d, const veil_exr_meta* meta)
{
    const int w = d->width, h = d->height;
    Imf::Header header(w, h);
    header.compression() = Imf::ZIPS_COMPRESSION;
    header.setType(Imf::DEEPSCANLINE);
    for (const char* n : k_names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
    add_meta(header, meta);
    // OpenEXR reads each pixel's samples through a pointer a channel: a
    // pointer a pixel and channel into d->samples, whose samples are
    // interleaved (VEIL_DEEP_CHANNELS floats apart)
    const size_t pixels = (size_t)w * (size_t)h;
    std::vector<const float*> first(pixels);
    size_t at = 0;
    for (size_t i = 0; i < pixels; ++i) {
        first[i] = d->samples + at * VEIL_DEEP_CHANNELS;
        at += d->counts[i];
    }
    fd_ostream os(fd, path);
    Imf::DeepScanLineOutputFile file(os, header);
    Imf::DeepFrameBuffer fb;
    fb.insertSampleCountSlice(Imf::Slice(Imf::UINT, (char*)d->counts, sizeof(uint32_t), sizeof(uint32_t) * (size_t)w));
    std::vector<std::vector<const float*>> per(VEIL_DEEP_CHANNELS, std::vector<const float*>(pixels));
    for (int c = 0; c < VEIL_DEEP_CHANNELS; ++c) {
        for (size_t i = 0; i < pixels; ++i) per[c][i] = first[i] + c;
        fb.insert(k_names[c], Imf::DeepSlice(Imf::FLOAT, (char*)per[c].data(), sizeof(float*), sizeof(float*) * (size_t)w,
                                             sizeof(float) * VEIL_DEEP_CHANNELS));
    }
    file.setFrameBuffer(fb);
    file.writePixels(h);
}

} // namespace

extern "C" veil_result veil__exr_write_imf(int fd, const char* path, int width, int height, int n,
                                           const char* const* names, const float* const* planes,
                                           const veil_exr_meta* meta, veil_error* err)
{
    return guarded(err, path, [&] {
        const veil_exr_format* fmt = meta ? &meta->format : nullptr;
        Imf::Header header(width, height);
        header.compression() = fmt && fmt->compression == VEIL_EXR_DWAB ? Imf::DWAB_COMPRESSION : Imf::DWAA_COMPRESSION;
        if (fmt && fmt->dwa_level > 0.0f) header.dwaCompressionLevel() = fmt->dwa_level;
        Imf::FrameBuffer fb;
        // the C++ library converts no float frame buffer into a half channel: half planes made here
        const size_t pixels = (size_t)width * (size_t)height;
        std::vector<std::vector<Imath::half>> halves;
        halves.reserve((size_t)n);
        for (int c = 0; c < n; ++c) {
            if (fmt && fmt->half && !veil_exr_keeps_float(names[c])) { // a half channel
                header.channels().insert(names[c], Imf::Channel(Imf::HALF));
                halves.emplace_back(planes[c], planes[c] + pixels); // float to half: round to nearest even
                fb.insert(names[c], Imf::Slice(Imf::HALF, (char*)halves.back().data(), sizeof(Imath::half),
                                               sizeof(Imath::half) * (size_t)width));
            } else {
                header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
                fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)planes[c], sizeof(float), sizeof(float) * (size_t)width));
            }
        }
        add_meta(header, meta);
        fd_ostream os(fd, path);
        const int threads = fmt && fmt->threads > 0 ? fmt->threads : veil_exr_threads();
        Imf::OutputFile file(os, header, threads > 1 ? threads : 0);
        file.setFrameBuffer(fb);
        file.writePixels(height);
    }, "the OpenEXR file");
}

extern "C" void veil_deep_image_free(veil_deep_image* d)
{
    if (!d) return;
    std::free(d->counts);
    std::free(d->samples);
    std::memset(d, 0, sizeof *d);
}

extern "C" veil_result veil_write_deep_exr(const char* path, const veil_deep_image* d, const veil_exr_meta* meta,
                                           veil_error* err)
{
    if (!path || !*path) return veil_fail(err, VEIL_ERR_INVALID, "veil_write_deep_exr: no output path given");
    if (!d || d->width <= 0 || d->height <= 0 || !d->counts)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: invalid deep image (%dx%d)", path, d ? d->width : 0,
                         d ? d->height : 0);
    size_t pixels = 0, sum = 0;
    if (!veil_mul_sizes((size_t)d->width, (size_t)d->height, 1, 1, &pixels))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: image size %dx%d is too large", path, d->width, d->height);
    for (size_t i = 0; i < pixels; ++i) sum += d->counts[i];
    if (sum != d->total || (sum && !d->samples))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: the deep image's counts add up to %zu samples, it holds %zu", path,
                         sum, d->samples ? d->total : (size_t)0);

    char* tmp = NULL;
    int fd = veil_open_temp_beside(path, &tmp);
    if (fd < 0 && errno == 0)
        return veil_fail(err, VEIL_ERR_IO, "%s: exists and is not a regular file; not replacing it", path);
    if (fd < 0)
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot create a temporary file beside it: %s", path, std::strerror(errno));
    veil_result r = guarded(err, path, [&] { write_file(fd, path, d, meta); });
    int close_errno = close(fd) != 0 ? errno : 0;
    if (r == VEIL_OK && close_errno)
        r = veil_fail(err, VEIL_ERR_IO, "%s: cannot write the deep OpenEXR file: closing %s failed: %s", path, tmp,
                      std::strerror(close_errno));
    if (r == VEIL_OK && rename(tmp, path) != 0)
        r = veil_fail(err, VEIL_ERR_IO, "%s: cannot move the temporary file %s into place: %s", path, tmp,
                      std::strerror(errno));
    if (r != VEIL_OK) unlink(tmp);
    veil_temp_forget(tmp);
    std::free(tmp);
    return r;
}
