// fft_pass.comp, fft_scatter.comp, spectrum_product.comp and fft_gather.comp (gpu::GlFft) against
// the DFT's definition summed here and against the CPU's FFTW convolution of the diffraction stage.

#include "diffraction/convolution.h"
#include "diffraction/psf.h"
#include "gpu/gl_context.h"
#include "gpu/gl_fft.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>

namespace ff::gpu {
namespace {

double relativeL2(const std::vector<std::complex<double>>& a, const std::vector<std::complex<double>>& b) {
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) num += std::norm(a[i] - b[i]), den += std::norm(b[i]);
    return std::sqrt(num / den);
}

TEST(GlFft, MatchesTheDftByItsDefinition) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    GlFft fft(*context);
    std::mt19937 rng(4);
    std::normal_distribution<double> g;
    // radix-4 passes alone, 4s and a 2, one side of length 1, 3s (one and several), 2s and 3s mixed
    for (auto [W, H] : {std::pair{64, 32}, std::pair{8, 128}, std::pair{1, 16}, std::pair{48, 36}, std::pair{54, 3},
                        std::pair{6, 81}}) {
        std::vector<std::complex<double>> x(static_cast<std::size_t>(W) * H);
        for (auto& v : x) v = {g(rng), g(rng)};
        for (bool inverse : {false, true}) {
            // X(u, v) = sum_{x, y} x(x, y) exp(-+ 2 pi i (u x / W + v y / H))
            std::vector<std::complex<double>> dft(x.size());
            const double s = inverse ? 2.0 * std::numbers::pi : -2.0 * std::numbers::pi;
            for (int v = 0; v < H; ++v)
                for (int u = 0; u < W; ++u) {
                    std::complex<double> acc = 0.0;
                    for (int y = 0; y < H; ++y)
                        for (int xx = 0; xx < W; ++xx)
                            acc += x[static_cast<std::size_t>(y) * W + xx] *
                                   std::polar(1.0, s * (double(u * xx % W) / W + double(v * y % H) / H));
                    dft[static_cast<std::size_t>(v) * W + u] = acc;
                }
            EXPECT_LT(relativeL2(fft.transform(x, W, H, inverse), dft), 1e-12)
                << W << "x" << H << " inverse " << inverse;
        }
    }
    EXPECT_THROW(fft.transform(std::vector<std::complex<double>>(15), 5, 3, false),
                 Error); // 5 is no product of 2s and 3s
}

TEST(GlFft, ConvolutionMatchesTheCpu) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    const int W = 45, H = 29;
    diffraction::Psf psf;
    psf.radius = 7;
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (auto& ch : psf.channel) {
        ch.resize(static_cast<std::size_t>(psf.width()) * psf.width());
        for (auto& v : ch) v = static_cast<float>(u(rng) * u(rng) * 0.01);
    }
    std::vector<float> lights(static_cast<std::size_t>(W) * H * 3, 0.0f);
    for (int k = 0; k < 10; ++k) // some at the frame's edges
        lights[(static_cast<std::size_t>(rng() % H) * W + rng() % W) * 3 + rng() % 3] =
            static_cast<float>(1e4 * u(rng));
    double offGl = 0.0, offCpu = 0.0;
    GlFft fft(*context);
    const auto gl = fft.convolve(lights, W, H, psf, &offGl), cpu = diffraction::convolve(lights, W, H, psf, &offCpu);
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < gl.size(); ++i)
        num += double(gl[i] - cpu[i]) * (gl[i] - cpu[i]), den += double(cpu[i]) * cpu[i];
    EXPECT_LT(std::sqrt(num / den), 1e-6); // float outputs of double transforms
    EXPECT_NEAR(offGl, offCpu, 1e-9 * offCpu);
    EXPECT_GT(offCpu, 0.0);
    // Through the diffraction layer too.
    const auto layer = diffraction::diffractionLayer(lights, W, H, psf, 1.0, nullptr, &fft);
    const auto layerCpu = diffraction::diffractionLayer(lights, W, H, psf, 1.0);
    for (std::size_t i = 0; i < layer.size(); ++i) EXPECT_NEAR(layer[i], layerCpu[i], 1e-6f * 1e4f);
}

// The kernel's spectra kept on the GPU between frames: frames whose lights reach differently (the
// same period, or another), a changed PSF, another frame size (a 128-wide period: an odd number of
// row passes) and the first frame again each match the CPU's convolution; a frame convolved again
// has the same bytes as the first time (nothing left over from the frames between).
TEST(GlFft, KeptKernelSpectraMatchTheCpuFrameAfterFrame) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    diffraction::PsfSettings s;
    s.pitchMm = 36.0 / 120;
    s.wavelengthsNm = {450.0, 550.0, 650.0};
    s.transform = 256;
    const diffraction::Psf six = diffraction::pixelPsf({6, 0.0, 8.0}, s),
                           five = diffraction::pixelPsf({5, 9.0, 11.0}, s);
    ASSERT_FALSE(six.far.empty());
    ASSERT_NE(diffraction::kernelFingerprint(six), diffraction::kernelFingerprint(five));
    struct Case {
        std::vector<float> lights;
        const diffraction::Psf* psf;
        int W = 120, H = 70;
    };
    const auto frame = [&](std::initializer_list<std::array<int, 2>> at, const diffraction::Psf* psf, int W = 120,
                           int H = 70) {
        std::vector<float> lights(static_cast<std::size_t>(W) * H * 3, 0.0f);
        for (const auto& [x, y] : at)
            for (int c = 0; c < 3; ++c)
                lights[(static_cast<std::size_t>(y) * W + x) * 3 + c] = 5e3f * static_cast<float>(c + 1);
        return Case{lights, psf, W, H};
    };
    GlFft fft(*context);
    const Case cases[] = {frame({{60, 35}}, &six),
                          frame({{50, 30}, {70, 40}}, &six),
                          frame({{2, 1}, {118, 68}}, &six),
                          frame({{50, 30}, {70, 40}}, &five),
                          frame({{30, 39}, {5, 0}}, &five, 60, 40),
                          frame({{20, 10}}, &five, 60, 40),
                          frame({{30, 39}, {5, 0}}, &five, 60, 40),
                          frame({{60, 35}}, &six)};
    std::vector<std::vector<float>> results;
    for (const Case& k : cases) {
        const int W = k.W, H = k.H;
        double offGl = 0.0, offCpu = 0.0, in = 0.0;
        for (float v : k.lights) in += v;
        const auto gl = fft.convolve(k.lights, W, H, *k.psf, &offGl);
        const auto cpu = diffraction::convolve(k.lights, W, H, *k.psf, &offCpu);
        double num = 0.0, den = 0.0;
        for (std::size_t i = 0; i < gl.size(); ++i)
            num += double(gl[i] - cpu[i]) * (gl[i] - cpu[i]), den += double(cpu[i]) * cpu[i];
        // The CPU transforms the far field in float (diffraction::convolve).
        EXPECT_LT(std::sqrt(num / den), 1e-5);
        EXPECT_NEAR(offGl, offCpu, 1e-5 * in);
        results.push_back(gl);
    }
    EXPECT_EQ(results[0], results[7]);
    EXPECT_EQ(results[4], results[6]);
}

} // namespace
} // namespace ff::gpu
