#include "trace/adaptive_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

using namespace ff;
using namespace ff::trace;

namespace {

double sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

// Relative L2 distance of a from the reference.
double relativeL2(const std::vector<double>& a, const std::vector<double>& ref) {
    double d = 0.0, r = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) d += (a[i] - ref[i]) * (a[i] - ref[i]), r += ref[i] * ref[i];
    return std::sqrt(d / r);
}

// Length of [lo, hi] inside [a, b].
double overlap(double lo, double hi, double a, double b) { return std::max(0.0, std::min(hi, b) - std::max(lo, a)); }

// The fold x = x0 + A u^2, y = y0 + B v of the pupil square [-1, 1]^2 (weight 1): a caustic along
// x = x0, where the irradiance A^-1/2 (x - x0)^-1/2 / B (both sheets) diverges. Pixel [X, X+1] x
// [Y, Y+1] receives the pupil area whose image lies in it: the u with u^2 in [(X - x0)/A, (X + 1 - x0)/A]
// on both sheets, 2 (sqrt(hi) - sqrt(lo)) over [0, 1], times the v with y in [Y, Y + 1].
struct Fold {
    double A = 40.0, B = 12.0, x0 = 10.3, y0 = 15.6;
    int W = 64, H = 32;

    PupilSampler sampler() const {
        return [f = *this](std::span<const glm::dvec2> p, std::span<PupilSample> out) {
            for (std::size_t i = 0; i < p.size(); ++i) out[i] = {{f.x0 + f.A * p[i].x * p[i].x, f.y0 + f.B * p[i].y}, 1.0, true};
        };
    }
    std::vector<double> exact() const {
        std::vector<double> img(static_cast<std::size_t>(W) * H, 0.0);
        for (int Y = 0; Y < H; ++Y) {
            const double v = overlap((Y - y0) / B, (Y + 1 - y0) / B, -1.0, 1.0);
            for (int X = 0; X < W; ++X) {
                const double lo = std::clamp((X - x0) / A, 0.0, 1.0), hi = std::clamp((X + 1 - x0) / A, 0.0, 1.0);
                img[static_cast<std::size_t>(Y) * W + X] = 2.0 * (std::sqrt(hi) - std::sqrt(lo)) * v;
            }
        }
        return img;
    }
};

} // namespace

TEST(AdaptiveGrid, AFoldIsDrawnAsItsExactPixelIntegralsWithoutSpokes) {
    const Fold f;
    const std::vector<double> exact = f.exact();
    // 8 x 8 starting cells over the square: the fold runs through the middle column of cells.
    AdaptiveGrid grid(8, -1.0, -1.0, 0.25, {}, RefineSettings{}, f.sampler());
    grid.refine(f.W, f.H);
    std::vector<double> img(exact.size(), 0.0);
    RasterStats st;
    grid.draw(1.0, {f.W, f.H, 1.0}, img, st);
    EXPECT_NEAR(sum(img), 4.0, 1e-12); // the pupil's area, weight 1: all of it lands in the frame
    EXPECT_LE(relativeL2(img, exact), 0.01);
    // No pixel brighter than the caustic's own column allows (exact integral, 2 % for the sub-pixel
    // spreading of the last folded cells).
    const double brightest = *std::max_element(exact.begin(), exact.end());
    for (std::size_t i = 0; i < img.size(); ++i) {
        ASSERT_GE(img[i], 0.0);
        ASSERT_LE(img[i], 1.02 * brightest) << "pixel " << i % f.W << "," << i / f.W;
    }
}

TEST(AdaptiveGrid, ACuspMatchesADensePointSampling) {
    // The Whitney cusp x = u^3 + u v, y = v (scaled to pixels): two fold lines v = -3 u^2 meet at a
    // cusp. Reference: 4096^2 points of the pupil square, each dropping its area into its pixel.
    const int W = 64, H = 32;
    auto map = [](double u, double v) { return glm::dvec2(32.3 + 12.0 * (u * u * u + u * v), 16.2 + 14.0 * v); };
    std::vector<double> ref(static_cast<std::size_t>(W) * H, 0.0);
    const int N = 4096;
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
            const glm::dvec2 p = map(-1.0 + (i + 0.5) * 2.0 / N, -1.0 + (j + 0.5) * 2.0 / N);
            ref[static_cast<std::size_t>(std::floor(p.y)) * W + static_cast<std::size_t>(std::floor(p.x))] += 4.0 / (double(N) * N);
        }
    PupilSampler sampler = [&](std::span<const glm::dvec2> p, std::span<PupilSample> out) {
        for (std::size_t i = 0; i < p.size(); ++i) out[i] = {map(p[i].x, p[i].y), 1.0, true};
    };
    AdaptiveGrid grid(8, -1.0, -1.0, 0.25, {}, RefineSettings{}, sampler);
    grid.refine(W, H);
    std::vector<double> img(ref.size(), 0.0);
    RasterStats st;
    grid.draw(1.0, {W, H, 1.0}, img, st);
    EXPECT_LE(relativeL2(img, ref), 0.01);
}
