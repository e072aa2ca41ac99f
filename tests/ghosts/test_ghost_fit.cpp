#include "ghosts/ghost_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

using namespace ff;
using namespace ff::ghosts;
using trace::RayResult;

namespace {

// A bundle of n x n cells of side h mapped one to one onto the sensor around (cx, cy): the
// irradiance there is the weight function itself, a profile whose widths are known exactly.
struct Synthetic {
    trace::Bundle b;
    std::vector<RayResult> c, k;
    double flux = 0.0;
};

// The grid's corner is at (x0, y0) of the pupil plane, by default where it centres the grid on (0, 0).
Synthetic synthetic(int n, double h, double cx, double cy, const std::function<double(double, double)>& weight,
                    double x0 = NAN, double y0 = NAN) {
    Synthetic s;
    s.b.n = n;
    s.b.cell = h;
    s.b.cellArea = h * h;
    s.b.x0 = std::isnan(x0) ? -0.5 * n * h : x0;
    s.b.y0 = std::isnan(y0) ? -0.5 * n * h : y0;
    s.b.rays.resize(static_cast<std::size_t>(n) * n);
    s.b.launched.assign(s.b.rays.size(), 1);
    auto ray = [&](double x, double y, double w) {
        RayResult r;
        r.status = optics::RayStatus::Ok;
        r.weight = w;
        r.sensorPoint = {cx + x, cy + y, 0.0};
        return r;
    };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = s.b.x0 + (i + 0.5) * h, y = s.b.y0 + (j + 0.5) * h;
            s.c.push_back(ray(x, y, weight(x, y)));
            s.flux += weight(x, y) * h * h;
        }
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) s.k.push_back(ray(s.b.x0 + i * h, s.b.y0 + j * h, 1.0));
    return s;
}

} // namespace

TEST(GhostFit, ProfilesIntegrateToTheirStatedAreas) {
    // Riemann sums of the unit-peak profiles against 2 pi sR sT and wR wT.
    for (Profile p : {Profile::Gaussian, Profile::Cos2}) {
        const double wr = 0.7, wt = 1.3, h = 0.005;
        double sum = 0.0;
        for (double u = -8; u <= 8; u += h)
            for (double v = -8; v <= 8; v += h) sum += profileValue(p, wr, wt, u, v) * h * h;
        EXPECT_NEAR(sum, profileArea(p, wr, wt), 1e-4 * profileArea(p, wr, wt)) << toString(p);
    }
}

TEST(GhostFit, RecoversAKnownGaussian) {
    // sigma_x (tangential) = 0.30 mm, sigma_y (radial) = 0.45 mm, centred at (1.0, 6.0).
    const double sx = 0.30, sy = 0.45;
    const Synthetic s = synthetic(120, 0.025, 1.0, 6.0, [&](double x, double y) {
        return std::exp(-0.5 * (x * x / (sx * sx) + y * y / (sy * sy)));
    });
    const GhostFit f = fitGhost(s.b, s.c, s.k, 1.0);
    EXPECT_NEAR(f.flux, s.flux, 1e-12 * s.flux); // the fit keeps the traced flux
    EXPECT_NEAR(f.centroidX, 1.0, 1e-9);
    EXPECT_NEAR(f.centroidY, 6.0, 1e-9);
    EXPECT_NEAR(f.sigmaT, sx, 0.01 * sx);
    EXPECT_NEAR(f.sigmaR, sy, 0.01 * sy);
    EXPECT_NEAR(f.gaussian.widthT, sx, 0.01 * sx);
    EXPECT_NEAR(f.gaussian.widthR, sy, 0.01 * sy);
    EXPECT_NEAR(f.gaussian.peak * profileArea(Profile::Gaussian, f.gaussian.widthR, f.gaussian.widthT), s.flux,
                1e-12 * s.flux);
    EXPECT_LT(f.gaussian.error, 0.01);
    EXPECT_GT(f.cos2.error, f.gaussian.error); // the other profile fits worse
    EXPECT_EQ(f.survivingFraction, 1.0);
}

TEST(GhostFit, RecoversAKnownCos2Bump) {
    // Half-widths w_x = 0.8 mm, w_y = 0.5 mm.
    const double wx = 0.8, wy = 0.5;
    const Synthetic s = synthetic(128, 0.02, -2.0, 3.0, [&](double x, double y) {
        if (std::abs(x) >= wx || std::abs(y) >= wy) return 0.0;
        const double a = std::cos(0.5 * std::numbers::pi * x / wx), b = std::cos(0.5 * std::numbers::pi * y / wy);
        return a * a * b * b;
    });
    const GhostFit f = fitGhost(s.b, s.c, s.k, 1.0);
    EXPECT_NEAR(f.flux, s.flux, 1e-12 * s.flux);
    EXPECT_NEAR(f.cos2.widthT, wx, 0.01 * wx);
    EXPECT_NEAR(f.cos2.widthR, wy, 0.01 * wy);
    EXPECT_LT(f.cos2.error, 0.02);
    EXPECT_GT(f.gaussian.error, f.cos2.error);
    // Moment match: the cos^2 bump's sigma is w / 2.766 (fourier.md; sigma^2 = w^2 (1/3 - 2/pi^2)).
    EXPECT_NEAR(f.sigmaT, wx * std::sqrt(1.0 / 3.0 - 2.0 / (std::numbers::pi * std::numbers::pi)), 0.01 * f.sigmaT);
}

TEST(GhostFit, AGhostWithNoSurvivingRayHasNoFlux) {
    Synthetic s = synthetic(8, 0.1, 0.0, 0.0, [](double, double) { return 1.0; });
    for (auto& r : s.c) r.status = optics::RayStatus::Blocked;
    const GhostFit f = fitGhost(s.b, s.c, s.k, 1.0);
    EXPECT_EQ(f.flux, 0.0);
    EXPECT_EQ(f.survivingFraction, 0.0);
}

// A ghost traced in two parts, each on a grid of its own (the lower half of its pupil on 60 x 60
// cells 0.05 mm wide, the upper half on 40 x 40 cells 0.075 mm wide): its flux is the parts' sum, its
// moments and its fitted widths are those of the Gaussian the two halves make up together.
TEST(GhostFit, AGhostTracedInPartsIsFittedAsAWhole) {
    const double sx = 0.30, sy = 0.45;
    const auto gaussian = [&](double x, double y) { return std::exp(-0.5 * (x * x / (sx * sx) + y * y / (sy * sy))); };
    const Synthetic lower = synthetic(60, 0.05, 1.0, 6.0, gaussian, -1.5, -3.0);
    const Synthetic upper = synthetic(40, 0.075, 1.0, 6.0, gaussian, -1.5, 0.0);
    const BundlePart parts[] = {{&lower.b, &lower.c, &lower.k}, {&upper.b, &upper.c, &upper.k}};
    const GhostFit f = fitGhost(parts, 1.0);
    EXPECT_NEAR(f.flux, lower.flux + upper.flux, 1e-12 * f.flux);
    EXPECT_NEAR(f.centroidX, 1.0, 1e-9);
    EXPECT_NEAR(f.centroidY, 6.0, 0.01 * sy); // the two halves' midpoint sums differ a little
    EXPECT_NEAR(f.sigmaT, sx, 0.01 * sx);
    EXPECT_NEAR(f.sigmaR, sy, 0.01 * sy);
    EXPECT_NEAR(f.gaussian.widthT, sx, 0.01 * sx);
    EXPECT_NEAR(f.gaussian.widthR, sy, 0.01 * sy);
    EXPECT_LT(f.gaussian.error, 0.02);
    EXPECT_EQ(f.survivingFraction, 1.0);
    // One part alone is half the Gaussian: its fit is off.
    const GhostFit half = fitGhost(lower.b, lower.c, lower.k, 1.0);
    EXPECT_GT(std::abs(half.centroidY - 6.0), 0.5 * sy);
}
