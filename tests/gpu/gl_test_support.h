#pragma once
// What the GL tests share: random ghost sets and image comparisons.

#include "fourier/aggregate.h"
#include "ghosts/shaped_ghosts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace ff::gpu::testing {

/// Ghosts of one shape at random positions in a W x H frame (some hanging over its edges), sizes
/// log-uniform in [minSize, maxSize], per-axis and per-channel widths, random fluxes.
inline std::vector<fourier::Ghost> randomGhosts(int count, fourier::Shape shape, int W, int H, unsigned seed,
                                                double minSize = 2.0, double maxSize = 20.0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<fourier::Ghost> g(static_cast<std::size_t>(count));
    for (auto& k : g) {
        k.shape = shape;
        k.x = (1.1 * u(rng) - 0.05) * W;
        k.y = (1.1 * u(rng) - 0.05) * H;
        const double s = minSize * std::pow(maxSize / minSize, u(rng)), aspect = 0.5 + u(rng);
        for (int c = 0; c < 3; ++c) {
            k.widthX[c] = s * (1.0 + 0.05 * c);
            k.widthY[c] = s * aspect;
            k.flux[c] = u(rng);
        }
    }
    return g;
}

struct Difference {
    double relativeL2 = 0.0; ///< ||a - b|| / ||b|| over all channels
    double worst = 0.0;      ///< largest |a - b|
    double peak = 0.0;       ///< largest |b|
};

inline Difference difference(const fourier::FlareImage& a, const fourier::FlareImage& b) {
    Difference d;
    double num = 0.0, den = 0.0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t p = 0; p < b.pixels(); ++p) {
            const double x = double(a.channel[c][p]) - b.channel[c][p];
            num += x * x;
            den += double(b.channel[c][p]) * b.channel[c][p];
            d.worst = std::max(d.worst, std::abs(x));
            d.peak = std::max(d.peak, std::abs(double(b.channel[c][p])));
        }
    d.relativeL2 = den > 0.0 ? std::sqrt(num / den) : std::sqrt(num);
    return d;
}

/// The same for one channel of flux per pixel (b the reference).
inline Difference difference(const std::vector<double>& a, const std::vector<double>& b) {
    Difference d;
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
        num += (a[i] - b[i]) * (a[i] - b[i]);
        den += b[i] * b[i];
        d.worst = std::max(d.worst, std::abs(a[i] - b[i]));
        d.peak = std::max(d.peak, std::abs(b[i]));
    }
    d.relativeL2 = den > 0.0 ? std::sqrt(num / den) : std::sqrt(num);
    return d;
}

/// Expects channels a to match the reference b: relative L2 and the largest difference (relative to
/// b's peak) within `tolerance` per channel.
template <class Channels>
void expectChannelsNear(const Channels& a, const Channels& b, double tolerance, const char* what = "channel") {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t c = 0; c < b.size(); ++c) {
        const Difference d = difference(a[c], b[c]);
        EXPECT_LE(d.relativeL2, tolerance) << what << " " << c;
        EXPECT_LE(d.worst, tolerance * d.peak) << what << " " << c;
    }
}

/// Expects a shaped render on the GPU to be the CPU's: the same triangles, its flux off the frame
/// (some, to 1e-6 of the total) and its channels within 1e-6.
inline void expectShapedRendersMatch(const ghosts::ShapedRender& gl, const ghosts::ShapedRender& cpu) {
    EXPECT_EQ(gl.triangles, cpu.triangles);
    EXPECT_GT(cpu.offImage, 0.0);
    EXPECT_NEAR(gl.offImage, cpu.offImage, 1e-6 * (cpu.deposited + cpu.offImage));
    expectChannelsNear(gl.channel, cpu.channel, 1e-6);
}

/// ||a - b|| / ||b|| over the coefficients of all channels.
inline double coefficientDifference(const fourier::Coefficients& a, const fourier::Coefficients& b) {
    double num = 0.0, den = 0.0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < b.z[c].size(); ++i) {
            num += (a.z[c][i] - b.z[c][i]) * (a.z[c][i] - b.z[c][i]);
            den += b.z[c][i] * b.z[c][i];
        }
    return std::sqrt(num / den);
}

} // namespace ff::gpu::testing
