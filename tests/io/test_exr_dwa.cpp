// The flat EXR writer's DWAA and DWAB (issue 42), which go through OpenEXR's C++ library
// (io/exr_deep.h: OpenEXRCore 3.1 encodes and decodes no DWA), read back by that library here (veil's
// own reader is OpenEXRCore's). On a smooth image (a sum of sines, as a render's light is):
//  - every channel present, half where asked except the distances and P (veil_exr_keeps_float);
//  - DWA compresses R, G, B (and Y) lossily, half and float alike; A and the rest stay lossless: in
//    half the float rounded to half (within 2^-11 relative), in float bit for bit;
//  - R, G, B within the codec's loss. DWA quantises the DCT of 8x8 blocks in a perceptual space: no
//    closed-form bound, so the test measures it (printed) and asserts the RMS relative error below
//    1e-2 at the default level 45, which separates the codec's loss (measured 4.2e-3 here, 7.1e-4
//    at level 1, 1.5e-2 at 450) from a wiring error (a channel written from another's plane:
//    errors of order 1); and the level honoured: 1 loses no more than 45, 450 more than 45.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <unistd.h>
#include <vector>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

extern "C" {
#include "io/image.h"
#include "support/check.h"
}

namespace {
const int W = 97, H = 83, N = 7;
const char* const names[N] = {"R", "G", "B", "A", "Z", "depth", "P"};

// The RMS relative error of the colour channels R, G, B (and the checks of the others) of one file.
double check_file(const char* path, int compression, int as_half, float level, const std::vector<std::vector<float>>& p)
{
    veil_exr_meta m{};
    m.format.half = as_half, m.format.compression = compression, m.format.dwa_level = level;
    const float* pl[N];
    for (int c = 0; c < N; ++c) pl[c] = p[c].data();
    veil_error err{};
    veil_result r = veil_write_exr_planes_meta(path, W, H, N, names, pl, &m, &err);
    CHECK(r == VEIL_OK, "%s: %s", path, err.msg);
    if (r != VEIL_OK) return 1e30;
    Imf::InputFile f(path);
    CHECK(f.header().compression() == (compression == VEIL_EXR_DWAB ? Imf::DWAB_COMPRESSION : Imf::DWAA_COMPRESSION),
          "%s: compression %d", path, (int)f.header().compression());
    Imf::FrameBuffer fb;
    std::vector<std::vector<float>> g(N, std::vector<float>((size_t)W * H));
    for (int c = 0; c < N; ++c) fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)g[c].data(), 4, 4 * (size_t)W));
    f.setFrameBuffer(fb);
    f.readPixels(0, H - 1);
    double se = 0.0;
    for (int c = 0; c < N; ++c) {
        const Imf::Channel* ch = f.header().channels().findChannel(names[c]);
        const bool is_half = as_half && !veil_exr_keeps_float(names[c]);
        CHECK(ch && ch->type == (is_half ? Imf::HALF : Imf::FLOAT), "%s: channel %s's type", path, names[c]);
        int bad = 0;
        for (int i = 0; i < W * H; ++i) {
            const double want = p[c][i], d = std::fabs(g[c][i] - want) / std::fabs(want);
            if (c < 3) se += d * d;
            else if (is_half ? d > std::ldexp(1.0, -11) : g[c][i] != p[c][i]) ++bad;
        }
        CHECK(!bad, "%s: channel %s: %d values not as written (%s)", path, names[c], bad,
              is_half ? "half, lossless" : "float, bit for bit");
    }
    std::remove(path);
    return std::sqrt(se / (3.0 * W * H));
}
} // namespace

int main()
{
    std::vector<std::vector<float>> p(N, std::vector<float>((size_t)W * H));
    for (int c = 0; c < N; ++c)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                p[c][(size_t)y * W + x] = (float)((0.5 + 0.4 * std::sin(0.1 * x + 0.07 * y + c)) * (c == 4 ? 10.0 : 1.0));
    char path[64];
    std::snprintf(path, sizeof path, "test_exr_dwa_%ld.exr", (long)getpid());
    for (int comp : {VEIL_EXR_DWAA, VEIL_EXR_DWAB})
        for (int as_half = 0; as_half <= 1; ++as_half) {
            const double e45 = check_file(path, comp, as_half, 0.0f, p), e1 = check_file(path, comp, as_half, 1.0f, p),
                         e450 = check_file(path, comp, as_half, 450.0f, p);
            std::printf("%s %s: RMS relative error of R, G, B at level 1 %.3g, 45 %.3g, 450 %.3g\n",
                        veil_exr_compression_name(comp), as_half ? "half" : "float", e1, e45, e450);
            CHECK(e45 < 1e-2, "%s %s: RMS relative error %.3g at level 45", veil_exr_compression_name(comp),
                  as_half ? "half" : "float", e45);
            CHECK(e1 <= e45 && e450 > e45, "%s %s: the level is not honoured: %.3g, %.3g, %.3g at 1, 45, 450",
                  veil_exr_compression_name(comp), as_half ? "half" : "float", e1, e45, e450);
        }
    return check_finish();
}
