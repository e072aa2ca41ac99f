#include "trace/flare_raster.h"
#include "trace/traced_flare.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numeric>

using namespace ff;
using namespace ff::trace;
using optics::RayStatus;

namespace {

double sum(const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0);
}

} // namespace

TEST(FlareRaster, FrameConversionsAreInverse) {
    const ImageFrame f{1920, 1080, 0.01875};
    const glm::dvec2 p = f.sensorToPixel(3.2, -4.1);
    const glm::dvec2 s = f.pixelToSensor(p.x, p.y);
    EXPECT_NEAR(s.x, 3.2, 1e-12);
    EXPECT_NEAR(s.y, -4.1, 1e-12);
    EXPECT_NEAR(f.sensorToPixel(0.0, 0.0).x, 960.0, 1e-12);
    EXPECT_LT(f.sensorToPixel(0.0, 1.0).y, 540.0); // +y on the sensor is up in the image
}

TEST(Colour, FlatSpectrumIsWhiteAndMatchingFunctionsPeakWhereTheyShould) {
    // CIE 1931: ybar peaks near 555 nm at ~1; xbar has its main lobe near 600 nm, zbar near 445 nm.
    EXPECT_NEAR(cie1931(555.0)[1], 1.0, 0.02);
    EXPECT_GT(cie1931(600.0)[0], cie1931(500.0)[0]);
    EXPECT_GT(cie1931(445.0)[2], 1.7);
    for (int n : {0, 8, 16}) {
        std::vector<double> l;
        std::vector<std::array<double, 3>> w;
        colourWeights(n, l, w);
        for (int ch = 0; ch < 3; ++ch) {
            double white = 0.0;
            for (const auto& row : w) white += row[ch];
            EXPECT_NEAR(white, 1.0, 1e-12) << n;
        }
    }
}

namespace {

// A polygon clipped to the unit pixel [x, x + 1] x [y, y + 1] against its four sides (an independent
// per-pixel computation, cost ~ area, to check the edge raster).
std::vector<glm::dvec2> clippedToPixel(std::vector<glm::dvec2> p, double x, double y) {
    auto clip = [&](int axis, double v, bool keepAbove) {
        std::vector<glm::dvec2> out;
        for (std::size_t i = 0; i < p.size(); ++i) {
            const glm::dvec2 a = p[i], b = p[(i + 1) % p.size()];
            const bool ia = keepAbove ? a[axis] >= v : a[axis] <= v, ib = keepAbove ? b[axis] >= v : b[axis] <= v;
            if (ia) out.push_back(a);
            if (ia != ib) out.push_back(a + (b - a) * ((v - a[axis]) / (b[axis] - a[axis])));
        }
        p = out;
    };
    clip(0, x, true);
    clip(0, x + 1, false);
    clip(1, y, true);
    clip(1, y + 1, false);
    return p;
}

// Exact area of a polygon inside the unit pixel at (x, y).
double pixelCoverage(const std::vector<glm::dvec2>& poly, double x, double y) {
    const std::vector<glm::dvec2> p = clippedToPixel(poly, x, y);
    double area = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
        area += p[i].x * p[(i + 1) % p.size()].y - p[(i + 1) % p.size()].x * p[i].y;
    return 0.5 * std::abs(area);
}

// Uniform numbers in [0, 1) from a 64-bit linear congruential generator: the same on every platform.
struct Uniform {
    std::uint64_t state;
    double operator()() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>(state >> 11) * 0x1.0p-53;
    }
};

double polygonArea(const std::vector<glm::dvec2>& p) {
    double area = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
        area += p[i].x * p[(i + 1) % p.size()].y - p[(i + 1) % p.size()].x * p[i].y;
    return 0.5 * std::abs(area);
}

// The raster holds `expected` per pixel, and its stats split `total` into the drawn part (the sum of
// `expected`) and the part off the frame, which is not empty.
void expectDrawn(const CoverageRaster& raster, const RasterStats& st, const std::vector<double>& expected,
                 double total) {
    std::vector<double> image(expected.size(), 0.0);
    raster.addTo(image);
    double drawn = 0.0;
    for (std::size_t p = 0; p < image.size(); ++p) {
        EXPECT_NEAR(image[p], expected[p], 1e-9 * (1.0 + std::abs(expected[p]))) << p;
        drawn += expected[p];
    }
    EXPECT_NEAR(st.deposited, drawn, 1e-9 * total);
    EXPECT_NEAR(st.deposited + st.offImage, total, 1e-9 * total);
    EXPECT_LT(st.deposited, total); // some triangles reach past the frame
}

} // namespace

TEST(CoverageRaster, PolygonsOfEitherOrientationMatchPerPixelClipping) {
    // Random triangles of sizes from a tenth of a pixel to past the frame, both orientations, with
    // energies of many magnitudes, plus a concave polygon: every pixel holds the sum of energy /
    // area x its clipped area, and the stats split the energy into the drawn and the off-frame part.
    const ImageFrame frame{23, 17, 1.0};
    CoverageRaster raster(frame);
    RasterStats st;
    std::vector<double> expected(23 * 17, 0.0);
    Uniform uniform{12345};
    double total = 0.0;
    auto draw = [&](const std::vector<glm::dvec2>& poly, double e) {
        raster.polygon(poly, e, st);
        total += e;
        const double density = e / polygonArea(poly);
        for (int y = 0; y < frame.height; ++y)
            for (int x = 0; x < frame.width; ++x) expected[y * frame.width + x] += density * pixelCoverage(poly, x, y);
    };
    for (int t = 0; t < 200; ++t) {
        const double size = std::pow(10.0, -1.0 + 2.5 * uniform());
        const glm::dvec2 c(-3.0 + 29.0 * uniform(), -3.0 + 23.0 * uniform());
        std::vector<glm::dvec2> tri;
        for (int k = 0; k < 3; ++k) tri.push_back(c + size * glm::dvec2(uniform() - 0.5, uniform() - 0.5));
        if (polygonArea(tri) < 1e-6) continue;
        draw(tri, std::pow(10.0, -3.0 + 6.0 * uniform()));
    }
    draw({{2.5, 2.5}, {20.2, 3.1}, {8.0, 7.7}, {19.0, 15.5}, {1.7, 14.0}}, 50.0); // concave
    expectDrawn(raster, st, expected, total);
}

namespace {

// The integral of the plane through (p[k], value[k]), k < 3, over the polygon `poly` clipped to the
// unit pixel at (x, y): the clipped polygon's area times the plane at its centroid (both by the
// shoelace sums), an independent per-pixel computation.
double pixelIntegral(const std::vector<glm::dvec2>& poly, const std::array<glm::dvec2, 3>& p,
                     const std::array<double, 3>& value, double x, double y) {
    const std::vector<glm::dvec2> q = clippedToPixel(poly, x, y);
    double a2 = 0.0, cx = 0.0, cy = 0.0;
    for (std::size_t i = 0; i < q.size(); ++i) {
        const glm::dvec2 u = q[i], v = q[(i + 1) % q.size()];
        const double cross = u.x * v.y - v.x * u.y;
        a2 += cross;
        cx += (u.x + v.x) * cross;
        cy += (u.y + v.y) * cross;
    }
    if (a2 == 0.0) return 0.0;
    cx /= 3.0 * a2;
    cy /= 3.0 * a2;
    // The plane by barycentric coordinates of (cx, cy) in the triangle p.
    const glm::dvec2 e1 = p[1] - p[0], e2 = p[2] - p[0], r = glm::dvec2(cx, cy) - p[0];
    const double det = e1.x * e2.y - e1.y * e2.x;
    const double b1 = (r.x * e2.y - r.y * e2.x) / det, b2 = (e1.x * r.y - e1.y * r.x) / det;
    const double plane = (1.0 - b1 - b2) * value[0] + b1 * value[1] + b2 * value[2];
    return 0.5 * std::abs(a2) * plane;
}

} // namespace

TEST(CoverageRaster, LinearDensitiesMatchPerPixelIntegrals) {
    // Random triangles (a tenth of a pixel to past the frame, both orientations) with random
    // non-negative densities at their vertices, and a concave polygon cut from a plane: every pixel
    // holds the integral of the plane over the polygon within it, the total is each polygon's energy.
    const ImageFrame frame{23, 17, 1.0};
    CoverageRaster raster(frame);
    RasterStats st;
    std::vector<double> expected(23 * 17, 0.0);
    Uniform uniform{777};
    double total = 0.0;
    // The polygon, and the plane through value[k] at p[k]: energy, and gradient relative to the mean.
    auto draw = [&](const std::vector<glm::dvec2>& poly, const std::array<glm::dvec2, 3>& p,
                    const std::array<double, 3>& value) {
        double e = 0.0;
        for (int y = -40; y < 60; ++y)
            for (int x = -40; x < 60; ++x) {
                const double v = pixelIntegral(poly, p, value, x, y);
                e += v;
                if (x >= 0 && y >= 0 && x < frame.width && y < frame.height) expected[y * frame.width + x] += v;
            }
        const glm::dvec2 e1 = p[1] - p[0], e2 = p[2] - p[0];
        const double det = e1.x * e2.y - e1.y * e2.x;
        const glm::dvec2 grad(((value[1] - value[0]) * e2.y - (value[2] - value[0]) * e1.y) / det,
                              ((value[2] - value[0]) * e1.x - (value[1] - value[0]) * e2.x) / det);
        glm::dvec2 c(0.0);
        double a2 = 0.0;
        for (std::size_t i = 0; i < poly.size(); ++i) {
            const glm::dvec2 u = poly[i], v = poly[(i + 1) % poly.size()];
            const double cross = u.x * v.y - v.x * u.y;
            a2 += cross;
            c += (u + v) * cross;
        }
        c /= 3.0 * a2;
        const double mean = value[0] + grad.x * (c.x - p[0].x) + grad.y * (c.y - p[0].y); // the plane at the centroid
        raster.polygon(poly, e, grad / mean, st);
        total += e;
    };
    for (int t = 0; t < 200; ++t) {
        const double size = std::pow(10.0, -1.0 + 2.5 * uniform());
        const glm::dvec2 c(-3.0 + 29.0 * uniform(), -3.0 + 23.0 * uniform());
        std::array<glm::dvec2, 3> tri;
        for (auto& v : tri) v = c + size * glm::dvec2(uniform() - 0.5, uniform() - 0.5);
        if (polygonArea({tri.begin(), tri.end()}) < 1e-6) continue;
        const double scale = std::pow(10.0, -3.0 + 6.0 * uniform());
        std::array<double, 3> value{scale * uniform(), scale * uniform(), scale * uniform()};
        if (t % 7 == 0) value[t % 3] = 0.0; // a density reaching zero at a corner
        draw({tri.begin(), tri.end()}, tri, value);
    }
    // Concave, inside the triangle below whose plane stays positive over it.
    draw({{2.5, 2.5}, {20.2, 3.1}, {8.0, 7.7}, {19.0, 15.5}, {1.7, 14.0}}, {{{0.0, 0.0}, {30.0, 0.0}, {0.0, 30.0}}},
         {5.0, 1.0, 9.0});
    expectDrawn(raster, st, expected, total);
}

TEST(CoverageRaster, ReleaseGivesTheSameImageAsAddTo) {
    const ImageFrame frame{9, 5, 1.0};
    CoverageRaster raster(frame);
    RasterStats st;
    raster.polygon(std::vector<glm::dvec2>{{0.5, 0.5}, {8.2, 1.0}, {3.0, 4.9}}, 2.0, st);
    raster.point({4.3, 2.2}, 1.0, st);
    raster.pixel(8, 4, 0.5, st);
    raster.polygon(std::vector<glm::dvec2>{{1.2, 0.3}, {7.5, 4.6}, {0.4, 4.1}}, 1.5, {0.1, -0.05}, st);
    std::vector<double> a(45, 0.0);
    raster.addTo(a);
    const std::vector<double> b = std::move(raster).release();
    ASSERT_EQ(b.size(), a.size());
    for (std::size_t p = 0; p < a.size(); ++p) EXPECT_EQ(a[p], b[p]);
    EXPECT_NEAR(sum(a), 5.0, 1e-12);
}
