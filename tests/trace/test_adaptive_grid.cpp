#include "trace/adaptive_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

using namespace ff;
using namespace ff::trace;

namespace {

double sum(const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0);
}

// Relative L2 distance of a from the reference.
double relativeL2(const std::vector<double>& a, const std::vector<double>& ref) {
    double d = 0.0, r = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) d += (a[i] - ref[i]) * (a[i] - ref[i]), r += ref[i] * ref[i];
    return std::sqrt(d / r);
}

// Length of [lo, hi] inside [a, b].
double overlap(double lo, double hi, double a, double b) {
    return std::max(0.0, std::min(hi, b) - std::max(lo, a));
}

// The fold x = x0 + A u^2, y = y0 + B v of the pupil square [-1, 1]^2 (weight 1): a caustic along
// x = x0, where the irradiance A^-1/2 (x - x0)^-1/2 / B (both sheets) diverges. Pixel [X, X+1] x
// [Y, Y+1] receives the pupil area whose image lies in it: the u with u^2 in [(X - x0)/A, (X + 1 - x0)/A]
// on both sheets, 2 (sqrt(hi) - sqrt(lo)) over [0, 1], times the v with y in [Y, Y + 1].
struct Fold {
    double A = 40.0, B = 12.0, x0 = 10.3, y0 = 15.6;
    int W = 64, H = 32;

    PupilSampler sampler() const {
        return [f = *this](std::span<const glm::dvec2> p, std::span<PupilSample> out) {
            for (std::size_t i = 0; i < p.size(); ++i)
                out[i] = {{f.x0 + f.A * p[i].x * p[i].x, f.y0 + f.B * p[i].y}, 1.0, true};
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
    CoverageRaster raster({f.W, f.H, 1.0});
    grid.draw(1.0, raster, st);
    raster.addTo(img);
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
            ref[static_cast<std::size_t>(std::floor(p.y)) * W + static_cast<std::size_t>(std::floor(p.x))] +=
                4.0 / (double(N) * N);
        }
    PupilSampler sampler = [&](std::span<const glm::dvec2> p, std::span<PupilSample> out) {
        for (std::size_t i = 0; i < p.size(); ++i) out[i] = {map(p[i].x, p[i].y), 1.0, true};
    };
    AdaptiveGrid grid(8, -1.0, -1.0, 0.25, {}, RefineSettings{}, sampler);
    grid.refine(W, H);
    std::vector<double> img(ref.size(), 0.0);
    RasterStats st;
    CoverageRaster raster({W, H, 1.0});
    grid.draw(1.0, raster, st);
    raster.addTo(img);
    EXPECT_LE(relativeL2(img, ref), 0.01);
}

TEST(AdaptiveGrid, RefiningALitCellMovesLightButKeepsItsFlux) {
    // A smooth, non-affine map (a strong radial distortion) and a smoothly varying weight, every ray
    // arriving: refinement splits cells but the flux stays the starting grid's to rounding, and the
    // drawing deposits all of it.
    auto map = [](double u, double v) {
        const double k = 1.0 + 0.8 * (u * u + v * v);
        return glm::dvec2(40.0 + 25.0 * k * u, 30.0 + 25.0 * k * v);
    };
    PupilSampler sampler = [&](std::span<const glm::dvec2> p, std::span<PupilSample> out) {
        for (std::size_t i = 0; i < p.size(); ++i) out[i] = {map(p[i].x, p[i].y), 1.0 + 0.3 * p[i].x * p[i].y, true};
    };
    AdaptiveGrid grid(8, -1.0, -1.0, 0.25, {}, RefineSettings{}, sampler);
    const double before = grid.energy();
    const std::size_t startSamples = grid.stats().samples;
    grid.refine(80, 60);
    EXPECT_GT(grid.stats().samples, 4 * startSamples); // it did refine
    EXPECT_NEAR(grid.energy(), before, 1e-13 * before);
    std::vector<double> img(80 * 60, 0.0);
    RasterStats st;
    CoverageRaster raster({80, 60, 1.0});
    grid.draw(1.0, raster, st);
    raster.addTo(img);
    EXPECT_NEAR(sum(img) + st.offImage, before, 1e-12 * before);
}

TEST(AdaptiveGrid, AVignettingEdgeIsCutWhereItLies) {
    // Light passes a disc of radius 0.7 of the pupil square [-1, 1]^2 (32 x 32 starting cells, as the
    // renderer's default), mapped affinely onto pixels. The flux is the disc's area, less what the
    // straight cuts miss: cells crossed by the rim are cut along chords at most a cell's diagonal,
    // 0.088, long, and an inscribed polygon with chords c on a circle of radius r misses at most a
    // share c^2 / (6 r^2) = 2.6e-3 of its area. The image is the disc's pixel coverage, found by
    // point sampling of the pupil: 1920^2 points, 32 x 40 to a pixel, so every pixel inside counts
    // alike.
    const int W = 96, H = 64;
    auto map = [](double u, double v) { return glm::dvec2(48.3 + 30.0 * u, 31.7 + 24.0 * v); };
    auto lit = [](double u, double v) { return u * u + v * v < 0.49; };
    PupilSampler sampler = [&](std::span<const glm::dvec2> p, std::span<PupilSample> out) {
        for (std::size_t i = 0; i < p.size(); ++i) out[i] = {map(p[i].x, p[i].y), 1.0, lit(p[i].x, p[i].y)};
    };
    std::vector<double> ref(static_cast<std::size_t>(W) * H, 0.0);
    const int N = 1920;
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
            const double u = -1.0 + (i + 0.5) * 2.0 / N, v = -1.0 + (j + 0.5) * 2.0 / N;
            if (!lit(u, v)) continue;
            const glm::dvec2 p = map(u, v);
            ref[static_cast<std::size_t>(std::floor(p.y)) * W + static_cast<std::size_t>(std::floor(p.x))] +=
                4.0 / (double(N) * N);
        }
    AdaptiveGrid grid(32, -1.0, -1.0, 0.0625, {}, RefineSettings{}, sampler);
    grid.refine(W, H);
    const double disc = std::numbers::pi * 0.49;
    EXPECT_LE(grid.energy(), disc * (1.0 + 1e-6));
    EXPECT_GE(grid.energy(), disc * (1.0 - 2.6e-3));
    std::vector<double> img(ref.size(), 0.0);
    RasterStats st;
    CoverageRaster raster({W, H, 1.0});
    grid.draw(1.0, raster, st);
    raster.addTo(img);
    EXPECT_LE(relativeL2(img, ref), 0.01);
}
