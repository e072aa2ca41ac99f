#include "ghosts/ghost_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>

using namespace ff;
using namespace ff::ghosts;

namespace {

// Sensor mm = pixels (frame of pitch 1 mm on the axis; +y up in mm, down in pixels).
const trace::ImageFrame kMm{0, 0, 1.0};

void addSensorPolygon(ShapedPolygons& out, const std::vector<glm::dvec2>& mm, double energy) {
    std::vector<glm::dvec2> px;
    for (const glm::dvec2& p : mm) px.push_back(kMm.sensorToPixel(p.x, p.y));
    out.add(px.data(), px.size(), energy);
}

// A profile drawn as n x n squares of side h centred on (cx, cy), each carrying the profile's
// integral over it (by 8 x 8 midpoints): an image whose widths are known.
ShapedPolygons drawnProfile(int n, double h, double cx, double cy, const std::function<double(double, double)>& f,
                            double& flux) {
    ShapedPolygons out;
    flux = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x0 = (i - 0.5 * n) * h, y0 = (j - 0.5 * n) * h;
            double e = 0.0;
            for (int b = 0; b < 8; ++b)
                for (int a = 0; a < 8; ++a) e += f(x0 + (a + 0.5) * h / 8, y0 + (b + 0.5) * h / 8);
            e *= h * h / 64;
            if (e <= 0.0) continue;
            addSensorPolygon(
                out, {{cx + x0, cy + y0}, {cx + x0 + h, cy + y0}, {cx + x0 + h, cy + y0 + h}, {cx + x0, cy + y0 + h}},
                e);
            flux += e;
        }
    return out;
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

// The closed forms against brute force: random convex polygons (the hulls of 3-9 random points, some
// wound clockwise, some far from the origin, each with its own energy) sampled at the centres of a
// 1500 x 1500 grid over their box, every sample inside a polygon carrying its density x the cell's
// area. The sampling's error on a second moment is about (cell / size)^2 / 12 plus the boundary cells'
// share, ~1e-3 of the spread here; the closed forms are exact up to rounding.
TEST(GhostFit, PolygonMomentsMatchASupersampledRaster) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 6; ++trial) {
        ShapedPolygons ps;
        std::vector<std::vector<glm::dvec2>> polys;
        std::vector<double> energies;
        const glm::dvec2 offset = trial % 2 ? glm::dvec2(40.0 * u(rng), 25.0 * u(rng)) : glm::dvec2(0.0);
        for (int k = 0; k < 4; ++k) {
            std::vector<glm::dvec2> pts;
            const int count = 3 + static_cast<int>((u(rng) + 1.0) * 3.0);
            const glm::dvec2 centre = offset + glm::dvec2(3.0 * u(rng), 3.0 * u(rng));
            for (int i = 0; i < count; ++i) pts.push_back(centre + glm::dvec2(2.0 * u(rng), 1.5 * u(rng)));
            // The convex hull (monotone chain), counter-clockwise.
            std::sort(pts.begin(), pts.end(), [](auto a, auto b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
            auto cross = [](glm::dvec2 o, glm::dvec2 a, glm::dvec2 b) {
                return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
            };
            std::vector<glm::dvec2> hull;
            for (int pass = 0; pass < 2; ++pass) {
                const std::size_t start = hull.size();
                for (const glm::dvec2& p : pts) {
                    while (hull.size() >= start + 2 && cross(hull[hull.size() - 2], hull.back(), p) <= 0.0)
                        hull.pop_back();
                    hull.push_back(p);
                }
                hull.pop_back();
                std::reverse(pts.begin(), pts.end());
            }
            if (hull.size() < 3) continue;
            if (k % 2) std::reverse(hull.begin(), hull.end()); // clockwise
            const double e = 0.5 + 0.5 * (u(rng) + 1.0);
            addSensorPolygon(ps, hull, e);
            polys.push_back(hull);
            energies.push_back(e);
        }
        ASSERT_FALSE(polys.empty());
        const PolygonMoments m = polygonMoments(ps, kMm);
        // Brute force.
        double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
        for (const auto& p : polys)
            for (const glm::dvec2& v : p)
                x0 = std::min(x0, v.x), y0 = std::min(y0, v.y), x1 = std::max(x1, v.x), y1 = std::max(y1, v.y);
        const int n = 1500;
        const double hx = (x1 - x0) / n, hy = (y1 - y0) / n;
        std::array<double, 6> s{};
        for (std::size_t k = 0; k < polys.size(); ++k) {
            const auto& p = polys[k];
            double area = 0.0;
            for (std::size_t i = 0; i < p.size(); ++i) {
                const glm::dvec2 a = p[i], b = p[(i + 1) % p.size()];
                area += 0.5 * (a.x * b.y - b.x * a.y);
            }
            const double density = energies[k] / std::abs(area);
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    const glm::dvec2 q(x0 + (i + 0.5) * hx, y0 + (j + 0.5) * hy);
                    bool in = true, pos = false, neg = false;
                    for (std::size_t v = 0; v < p.size() && in; ++v) {
                        const glm::dvec2 a = p[v], b = p[(v + 1) % p.size()];
                        const double c = (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
                        pos = pos || c > 0.0, neg = neg || c < 0.0;
                        in = !(pos && neg);
                    }
                    if (!in) continue;
                    const double e = density * hx * hy;
                    s[0] += e, s[1] += e * q.x, s[2] += e * q.y, s[3] += e * q.x * q.x, s[4] += e * q.y * q.y,
                        s[5] += e * q.x * q.y;
                }
        }
        const double cx = s[1] / s[0], cy = s[2] / s[0];
        const double mxx = s[3] / s[0] - cx * cx, myy = s[4] / s[0] - cy * cy, mxy = s[5] / s[0] - cx * cy;
        double total = 0.0;
        for (double e : energies) total += e;
        EXPECT_NEAR(m.energy, total, 1e-12 * total);
        const double spread = std::sqrt(mxx + myy);
        EXPECT_NEAR(m.centroidX, cx, 2e-3 * spread) << "trial " << trial;
        EXPECT_NEAR(m.centroidY, cy, 2e-3 * spread) << "trial " << trial;
        EXPECT_NEAR(m.mxx, mxx, 3e-3 * spread * spread) << "trial " << trial;
        EXPECT_NEAR(m.myy, myy, 3e-3 * spread * spread) << "trial " << trial;
        EXPECT_NEAR(m.mxy, mxy, 3e-3 * spread * spread) << "trial " << trial;
    }
}

// Exact cases: a unit square's second moments are 1/12 about its centre, at any offset (no
// cancellation 1000 mm out); a polygon of no area is a point; light beyond maxRadius does not count.
TEST(GhostFit, PolygonMomentsAreExactForASquareAndCountOnlyWithinTheRadius) {
    ShapedPolygons ps;
    addSensorPolygon(ps, {{1000.0, 500.0}, {1001.0, 500.0}, {1001.0, 501.0}, {1000.0, 501.0}}, 2.0);
    PolygonMoments m = polygonMoments(ps, kMm);
    EXPECT_DOUBLE_EQ(m.energy, 2.0);
    EXPECT_NEAR(m.centroidX, 1000.5, 1e-9);
    EXPECT_NEAR(m.centroidY, 500.5, 1e-9);
    EXPECT_NEAR(m.mxx, 1.0 / 12.0, 1e-9);
    EXPECT_NEAR(m.myy, 1.0 / 12.0, 1e-9);
    EXPECT_NEAR(m.mxy, 0.0, 1e-9);
    ShapedPolygons point;
    addSensorPolygon(point, {{3.0, 4.0}, {3.0, 4.0}, {3.0, 4.0}}, 1.0);
    addSensorPolygon(point, {{-3.0, 4.0}, {-3.0, 4.0}, {-3.0, 4.0}}, 1.0);
    m = polygonMoments(point, kMm);
    EXPECT_DOUBLE_EQ(m.energy, 2.0);
    EXPECT_NEAR(m.centroidX, 0.0, 1e-12);
    EXPECT_NEAR(m.mxx, 9.0, 1e-12);
    EXPECT_NEAR(m.myy, 0.0, 1e-12);
    m = polygonMoments(ps, kMm, 100.0); // the square lies 1118 mm out
    EXPECT_EQ(m.energy, 0.0);
}

TEST(GhostFit, RecoversAKnownGaussian) {
    // sigma_x (tangential) = 0.30 mm, sigma_y (radial) = 0.45 mm, centred at (1.0, 6.0).
    const double sx = 0.30, sy = 0.45;
    double flux = 0.0;
    const ShapedPolygons ps = drawnProfile(
        120, 0.025, 1.0, 6.0,
        [&](double x, double y) { return std::exp(-0.5 * (x * x / (sx * sx) + y * y / (sy * sy))); }, flux);
    const GhostFit f = fitGhost(ps, kMm);
    EXPECT_NEAR(f.flux, flux, 1e-12 * flux); // the fit keeps the drawn flux
    EXPECT_NEAR(f.centroidX, 1.0, 1e-6);
    EXPECT_NEAR(f.centroidY, 6.0, 1e-6);
    // The squares add h^2 / 12 to each moment (0.4 % of sx^2 here).
    EXPECT_NEAR(f.sigmaT, sx, 0.01 * sx);
    EXPECT_NEAR(f.sigmaR, sy, 0.01 * sy);
    EXPECT_NEAR(f.gaussian.widthT, sx, 0.01 * sx);
    EXPECT_NEAR(f.gaussian.widthR, sy, 0.01 * sy);
    EXPECT_NEAR(f.gaussian.peak * profileArea(Profile::Gaussian, f.gaussian.widthR, f.gaussian.widthT), flux,
                1e-12 * flux);
    EXPECT_LT(f.gaussian.error, 0.01);
    EXPECT_GT(f.cos2.error, f.gaussian.error); // the other profile fits worse
}

TEST(GhostFit, RecoversAKnownCos2Bump) {
    // Half-widths w_x = 0.8 mm, w_y = 0.5 mm.
    const double wx = 0.8, wy = 0.5;
    double flux = 0.0;
    const ShapedPolygons ps = drawnProfile(
        128, 0.02, -2.0, 3.0,
        [&](double x, double y) {
            if (std::abs(x) >= wx || std::abs(y) >= wy) return 0.0;
            const double a = std::cos(0.5 * std::numbers::pi * x / wx), b = std::cos(0.5 * std::numbers::pi * y / wy);
            return a * a * b * b;
        },
        flux);
    const GhostFit f = fitGhost(ps, kMm);
    EXPECT_NEAR(f.flux, flux, 1e-12 * flux);
    EXPECT_NEAR(f.cos2.widthT, wx, 0.01 * wx);
    EXPECT_NEAR(f.cos2.widthR, wy, 0.01 * wy);
    EXPECT_LT(f.cos2.error, 0.02);
    EXPECT_GT(f.gaussian.error, f.cos2.error);
    // Moment match: the cos^2 bump's sigma is w / 2.766 (fourier.md; sigma^2 = w^2 (1/3 - 2/pi^2)).
    EXPECT_NEAR(f.sigmaT, wx * std::sqrt(1.0 / 3.0 - 2.0 / (std::numbers::pi * std::numbers::pi)), 0.01 * f.sigmaT);
}

TEST(GhostFit, AGhostWithNoLightHasNoFlux) {
    const GhostFit f = fitGhost(ShapedPolygons{}, kMm);
    EXPECT_EQ(f.flux, 0.0);
    EXPECT_EQ(f.gaussian.peak, 0.0);
}
