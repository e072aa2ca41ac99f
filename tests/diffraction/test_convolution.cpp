// The FFT convolution of the lights' image with the PSF against the direct sum (zero outside the
// frame), and the diffraction layer's energy rule.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "diffraction/convolution.h"

namespace ff::diffraction {
namespace {

Psf randomKernel(int radius, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Psf psf;
    psf.radius = radius;
    const int w = psf.width();
    for (auto& ch : psf.channel) {
        ch.resize(static_cast<std::size_t>(w) * w);
        double sum = 0.0;
        for (auto& v : ch) sum += (v = static_cast<float>(u(rng) * u(rng)));
        for (auto& v : ch) v = static_cast<float>(v / sum);
    }
    return psf;
}

TEST(Convolution, MatchesTheDirectSum) {
    const int W = 37, H = 23;
    const Psf psf = randomKernel(6, 3);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<float> image(static_cast<std::size_t>(W) * H * 3, 0.0f);
    for (int k = 0; k < 12; ++k) // lights, some at the frame's edges
        for (int c = 0; c < 3; ++c)
            image[(static_cast<std::size_t>(rng() % H) * W + rng() % W) * 3 + c] = static_cast<float>(100.0 * u(rng));
    double off = 0.0;
    const auto fft = convolve(image, W, H, psf, &off);
    double num = 0.0, den = 0.0, in = 0.0, kept = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                double direct = 0.0;
                for (int dy = -psf.radius; dy <= psf.radius; ++dy)
                    for (int dx = -psf.radius; dx <= psf.radius; ++dx) {
                        const int sx = x - dx, sy = y - dy;
                        if (sx < 0 || sy < 0 || sx >= W || sy >= H) continue;
                        direct += image[(static_cast<std::size_t>(sy) * W + sx) * 3 + c] * double(psf.at(c, dx, dy));
                    }
                const double d = fft[(static_cast<std::size_t>(y) * W + x) * 3 + c] - direct;
                num += d * d;
                den += direct * direct;
                in += image[(static_cast<std::size_t>(y) * W + x) * 3 + c];
                kept += direct;
            }
    EXPECT_LT(std::sqrt(num / den), 1e-5);
    EXPECT_NEAR(off, in - kept, 1e-4 * in);
    EXPECT_GT(off, 0.0);
}

// One light in the middle: the layer is the kernel around it minus the light, summing to zero; it is
// linear in the light and in the gain.
TEST(Convolution, TheLayerRedistributesTheLightsFlux) {
    const int W = 41, H = 41;
    const Psf psf = randomKernel(8, 9);
    std::vector<float> lights(static_cast<std::size_t>(W) * H * 3, 0.0f);
    const std::size_t centre = (static_cast<std::size_t>(20) * W + 20) * 3;
    lights[centre] = 500.0f, lights[centre + 1] = 200.0f, lights[centre + 2] = 50.0f;
    double off = 0.0;
    const auto layer = diffractionLayer(lights, W, H, psf, 1.0, &off);
    EXPECT_NEAR(off, 0.0, 1e-3);
    std::array<double, 3> sum{};
    for (std::size_t i = 0; i < layer.size(); ++i) sum[i % 3] += layer[i];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[static_cast<std::size_t>(c)], 0.0, 1e-4 * 500.0) << c;
    for (int c = 0; c < 3; ++c)
        for (int dy = -8; dy <= 8; ++dy)
            for (int dx = -8; dx <= 8; ++dx) {
                const float light = lights[centre + static_cast<std::size_t>(c)];
                const float expected = light * psf.at(c, dx, dy) - (dx == 0 && dy == 0 ? light : 0.0f);
                EXPECT_NEAR(layer[(static_cast<std::size_t>(20 + dy) * W + (20 + dx)) * 3 + c], expected, 1e-4 * light);
            }
    std::vector<float> doubled = lights;
    for (float& v : doubled) v *= 2.0f;
    const auto twice = diffractionLayer(doubled, W, H, psf, 1.0);
    const auto half = diffractionLayer(lights, W, H, psf, 0.5);
    for (std::size_t i = 0; i < layer.size(); ++i) {
        EXPECT_NEAR(twice[i], 2.0f * layer[i], 1e-4f * 500.0f);
        EXPECT_NEAR(half[i], 0.5f * layer[i], 1e-4f * 500.0f);
    }
}

} // namespace
} // namespace ff::diffraction
