// Coefficients of sampled profiles: a Gaussian sampled as cell integrals against the closed form
// written here (the continuous profile's series), and a non-separable profile reproduced by its
// series.

#include "core/error.h"
#include "fourier/evaluate.h"
#include "fourier/sampled.h"
#include "fourier/sampled_gaussian_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>

namespace ff::fourier {
namespace {

constexpr double kPi = std::numbers::pi;
using testing::gaussianTerm;
using testing::sampledGaussian;

TEST(SampledCoefficients, SampledGaussianMatchesTheClosedForm) {
    const double rgb[3] = {1.0, 0.5, 0.25};
    for (double step : {1.0, 0.5, 2.0}) {
        const double cx = 100.3, cy = 80.7, sx = 3.0, sy = 5.0;
        Coefficients z;
        z.n = z.m = 48;
        z.periodX = 256.0;
        z.periodY = 192.0;
        for (auto& ch : z.z) ch.assign(static_cast<std::size_t>(4) * z.n * z.m, 0.0);
        accumulateSampled({sampledGaussian(cx, cy, sx, sy, step, rgb)}, z);
        const double a00 = 1.0 / (z.periodX * z.periodY);
        double worst = 0.0;
        for (int c = 0; c < 3; ++c)
            for (int n = 0; n < z.n; ++n)
                for (int m = 0; m < z.m; ++m) {
                    const double norm = 1.0 / (2.0 * kPi * sx * sy) * rgb[c];
                    const auto [gc, gs] = gaussianTerm(n, sx, cx, z.periodX);
                    const auto [hc, hs] = gaussianTerm(m, sy, cy, z.periodY);
                    worst = std::max({worst, std::abs(z.at(c, n, m) - norm * gc * hc),
                                      std::abs(z.at(c, n, z.m + m) - norm * gc * hs),
                                      std::abs(z.at(c, z.n + n, m) - norm * gs * hc),
                                      std::abs(z.at(c, z.n + n, z.m + m) - norm * gs * hs)});
                }
        // Float32 samples: each carries a relative rounding of 6e-8.
        EXPECT_LT(worst, 1e-6 * a00) << "step " << step;
    }
}

TEST(SampledCoefficients, NonSeparableProfileIsReproducedByItsSeries) {
    // A rotated anisotropic Gaussian (not separable on x and y) sampled on the pixel grid: its
    // series, evaluated with the pixel-integrating basis, gives back the samples.
    const int W = 96, H = 64;
    SampledGhost g;
    g.x0 = 30.0;
    g.y0 = 16.0;
    g.width = 40;
    g.height = 32;
    const double cx = 50.2, cy = 31.6, a = 0.6, s1 = 5.0, s2 = 2.5;
    // Cell integrals by a 16 x 16 midpoint rule (the profile is smooth on that scale).
    for (int j = 0; j < g.height; ++j)
        for (int i = 0; i < g.width; ++i) {
            double v = 0.0;
            for (int q = 0; q < 16; ++q)
                for (int p = 0; p < 16; ++p) {
                    const double x = g.x0 + i + (p + 0.5) / 16.0 - cx, y = g.y0 + j + (q + 0.5) / 16.0 - cy;
                    const double u = std::cos(a) * x + std::sin(a) * y, w = -std::sin(a) * x + std::cos(a) * y;
                    v += std::exp(-0.5 * (u * u / (s1 * s1) + w * w / (s2 * s2))) / 256.0;
                }
            for (int c = 0; c < 3; ++c) g.values.push_back(static_cast<float>(v * (1.0 + c)));
        }
    Coefficients z;
    z.n = 64;
    z.m = 48;
    z.periodX = 128.0;
    z.periodY = 96.0;
    for (auto& ch : z.z) ch.assign(static_cast<std::size_t>(4) * z.n * z.m, 0.0);
    accumulateSampled({g}, z);
    FlareImage image(W, H);
    evaluate(z, Evaluation::Matrix, image);
    double num = 0.0, den = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const bool inside = x >= g.x0 && x < g.x0 + g.width && y >= g.y0 && y < g.y0 + g.height;
                const double want =
                    inside ? g.values[(static_cast<std::size_t>(y - 16) * g.width + (x - 30)) * 3 + c] : 0.0;
                const double d = image.channel[c][static_cast<std::size_t>(y) * W + x] - want;
                num += d * d;
                den += want * want;
            }
    // The profile's spectrum beyond 64 / 128 cycles per pixel is below 1e-6 of its peak.
    EXPECT_LT(std::sqrt(num / den), 1e-5);
}

// One grid spanning the period through the FFT: the same coefficients as the sums of the definition
// (accumulateSampled), for random cells (every frequency up to the grid's Nyquist present).
TEST(SampledCoefficients, GridThroughTheFftMatchesTheDefinition) {
    SampledGhost g;
    g.step = 4.0;
    g.width = 48;
    g.height = 40;
    g.x0 = -3.5 * g.step; // cell centres at multiples of the step
    g.y0 = -1.5 * g.step;
    std::uint32_t state = 12345u;
    for (int k = 0; k < g.width * g.height * 3; ++k) {
        state = state * 1664525u + 1013904223u;
        g.values.push_back(static_cast<float>(state >> 8) / float(1 << 24));
    }
    auto zeros = [&](int n, int m) {
        Coefficients z;
        z.n = n;
        z.m = m;
        z.periodX = g.width * g.step;
        z.periodY = g.height * g.step;
        for (auto& ch : z.z) ch.assign(static_cast<std::size_t>(4) * z.n * z.m, 0.0);
        return z;
    };
    Coefficients fft = zeros(24, 20), sums = zeros(24, 20);
    accumulateSampledGrid(g, fft);
    accumulateSampled({g}, sums);
    double worst = 0.0, largest = 0.0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t k = 0; k < sums.z[c].size(); ++k) {
            worst = std::max(worst, std::abs(fft.z[c][k] - sums.z[c][k]));
            largest = std::max(largest, std::abs(sums.z[c][k]));
        }
    // Float32 transforms of 1920 cells: a few 1e-7 of the largest coefficient.
    EXPECT_LT(worst, 2e-6 * largest);
    Coefficients tooMany = zeros(25, 20);
    EXPECT_THROW(accumulateSampledGrid(g, tooMany), Error);
    SampledGhost shifted = g;
    shifted.x0 += 1.0;
    EXPECT_THROW(accumulateSampledGrid(shifted, fft), Error);
    SampledGhost narrow = g;
    narrow.width -= 1;
    narrow.values.resize(static_cast<std::size_t>(narrow.width) * narrow.height * 3);
    EXPECT_THROW(accumulateSampledGrid(narrow, fft), Error);
}

TEST(SampledCoefficients, RefusesTermsAboveTheCellsNyquistFrequency) {
    const double rgb[3] = {1.0, 1.0, 1.0};
    Coefficients z;
    z.n = z.m = 64;
    z.periodX = z.periodY = 128.0;
    for (auto& ch : z.z) ch.assign(static_cast<std::size_t>(4) * z.n * z.m, 0.0);
    EXPECT_THROW(accumulateSampled({sampledGaussian(60.0, 60.0, 6.0, 6.0, 2.0, rgb)}, z), Error);
    SampledGhost bad;
    bad.width = 3;
    bad.height = 3;
    bad.values.assign(5, 0.0f);
    EXPECT_THROW(accumulateSampled({bad}, z), Error);
}

} // namespace
} // namespace ff::fourier
