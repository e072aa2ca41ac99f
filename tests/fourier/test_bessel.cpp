// The Fourier-Bessel variant: its Bessel values, its zeros, and the aggregated image against the
// analytic sum of the same (isotropic Gaussian) ghosts at pixel centres.

#include "core/error.h"
#include "fourier/bessel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace ff::fourier {
namespace {

TEST(FourierBessel, SeriesMatchesTheStandardLibrary) {
    std::vector<double> j(60);
    for (double x : {0.0, 1e-3, 0.5, 3.0, 17.3, 55.0, 240.0}) {
        besselSeries(x, 60, j.data());
        for (int m = 0; m < 60; ++m)
            EXPECT_NEAR(j[static_cast<std::size_t>(m)], std::cyl_bessel_j(double(m), x), 1e-12)
                << "x " << x << " m " << m;
    }
}

TEST(FourierBessel, ZerosAreZerosOfJ0) {
    const auto z = besselZeros(200);
    EXPECT_NEAR(z[0], 2.404825557695773, 1e-12); // A&S table 9.5
    for (std::size_t i = 0; i < z.size(); ++i) {
        EXPECT_NEAR(std::cyl_bessel_j(0.0, z[i]), 0.0, 1e-12);
        if (i > 0) {
            EXPECT_NEAR(z[i] - z[i - 1], std::numbers::pi, 0.03); // zeros are ~pi apart (3.115 for the first gap)
        }
    }
}

// Sum of isotropic Gaussians sampled at pixel centres, written out here.
std::vector<double> analytic(const std::vector<Ghost>& ghosts, int W, int H, int c) {
    std::vector<double> img(static_cast<std::size_t>(W) * H, 0.0);
    for (const Ghost& g : ghosts) {
        const double s2 = g.widthX[c] * g.widthY[c]; // geometric-mean sigma, squared
        const double peak = g.flux[c] / (2.0 * std::numbers::pi * s2);
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const double dx = x + 0.5 - g.x, dy = y + 0.5 - g.y;
                img[static_cast<std::size_t>(y) * W + x] += peak * std::exp(-0.5 * (dx * dx + dy * dy) / s2);
            }
    }
    return img;
}

TEST(FourierBessel, MatchesTheAnalyticSumWithinTheBudget) {
    const int W = 160, H = 96;
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Ghost> ghosts(25);
    for (Ghost& g : ghosts) {
        g.x = u(rng) * W;
        g.y = u(rng) * H;
        const double s = 4.0 * std::pow(5.0, u(rng)), aspect = 0.7 + 0.6 * u(rng);
        for (int c = 0; c < 3; ++c) {
            g.widthX[c] = s * (1.0 + 0.05 * c);
            g.widthY[c] = s * aspect * (1.0 + 0.05 * c);
            g.flux[c] = 0.5 + u(rng);
        }
    }
    for (double budget : {1e-2, 1e-3}) {
        FourierSettings s;
        s.basis = Basis::Bessel;
        s.error = budget;
        s.hybrid = false;
        const FourierRender r = renderBessel(ghosts, W, H, s);
        EXPECT_EQ(r.plan.fourier, ghosts.size());
        double num = 0.0, den = 0.0;
        for (int c = 0; c < 3; ++c) {
            const auto ref = analytic(ghosts, W, H, c);
            for (std::size_t p = 0; p < ref.size(); ++p) {
                const double d = r.image.channel[c][p] - ref[p];
                num += d * d;
                den += ref[p] * ref[p];
            }
        }
        EXPECT_LE(std::sqrt(num / den), budget) << r.plan.describe();
    }
}

TEST(FourierBessel, RefusesCos2Ghosts) {
    Ghost g;
    g.shape = Shape::Cos2;
    g.widthX = g.widthY = {5, 5, 5};
    g.flux = {1, 1, 1};
    FourierSettings s;
    s.basis = Basis::Bessel;
    EXPECT_THROW(renderBessel({g}, 32, 32, s), Error);
}

} // namespace
} // namespace ff::fourier
