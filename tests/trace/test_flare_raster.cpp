#include "trace/flare_raster.h"
#include "trace/traced_flare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

using namespace ff;
using namespace ff::trace;
using optics::RayStatus;

namespace {

// A synthetic bundle whose rays land on an affine image of the pupil grid: sensor = A pupil + c.
struct Synthetic {
    Bundle centres;
    std::vector<RayResult> c, k;
};

Synthetic affine(int n, double cell, double a11, double a12, double a21, double a22, double cx, double cy) {
    Synthetic s;
    Bundle& b = s.centres;
    b.n = n;
    b.cell = cell;
    b.cellArea = cell * cell;
    b.x0 = b.y0 = -0.5 * n * cell;
    b.rays.resize(static_cast<std::size_t>(n) * n);
    b.launched.assign(b.rays.size(), 1);
    auto land = [&](double x, double y) {
        RayResult r;
        r.status = RayStatus::Ok;
        r.weight = 1.0;
        r.sensorPoint = {a11 * x + a12 * y + cx, a21 * x + a22 * y + cy, 0.0};
        return r;
    };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) s.c.push_back(land(b.x0 + (i + 0.5) * cell, b.y0 + (j + 0.5) * cell));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) s.k.push_back(land(b.x0 + i * cell, b.y0 + j * cell));
    return s;
}

double sum(const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0);
}

} // namespace

TEST(FlareRaster, PixelAlignedCellsCoverTheirPixelsExactly) {
    // 4 x 4 cells of 1 mm mapped 1:1 onto 1 mm pixels (pitch 1): every covered pixel receives exactly
    // its cell's energy (weight 1 x area 1), the rest nothing.
    const ImageFrame frame{16, 16, 1.0};
    const Synthetic s = affine(4, 1.0, 1, 0, 0, 1, 0.0, 0.0);
    std::vector<double> image(256, 0.0);
    RasterStats st;
    rasterizeCells(s.centres, s.c, s.k, 1.0, frame, image, st);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const bool covered = x >= 6 && x < 10 && y >= 6 && y < 10;
            EXPECT_NEAR(image[y * 16 + x], covered ? 1.0 : 0.0, 1e-12) << x << "," << y;
        }
    EXPECT_EQ(st.quads, 16u);
    EXPECT_EQ(st.splats, 0u);
}

TEST(FlareRaster, FluxIsConservedUnderShearAndMagnification) {
    // A sheared, rotated, magnified mapping: the image total equals the sum of the rays' energies.
    // The landing points span |x| <= 3.98 mm and -4.52 <= y <= 4.12 mm: inside a 10 x 10 mm frame.
    const ImageFrame frame{200, 200, 0.05};
    const Synthetic s = affine(32, 0.1, 1.7, 0.6, -0.4, 2.3, 0.3, -0.2);
    std::vector<double> image(200 * 200, 0.0);
    RasterStats st;
    rasterizeCells(s.centres, s.c, s.k, 2.5, frame, image, st);
    const double expected = 32 * 32 * 0.1 * 0.1 * 2.5;
    EXPECT_EQ(st.offImage, 0.0);
    EXPECT_NEAR(sum(image), expected, 1e-4 * expected);
    EXPECT_NEAR(st.deposited, expected, 1e-4 * expected);
    // Cropped to a frame 7.5 mm high, what is drawn plus what fell outside is still the total.
    const ImageFrame cropped{200, 150, 0.05};
    std::vector<double> small(200 * 150, 0.0);
    RasterStats cs;
    rasterizeCells(s.centres, s.c, s.k, 2.5, cropped, small, cs);
    EXPECT_GT(cs.offImage, 0.0);
    EXPECT_NEAR(sum(small), cs.deposited, 1e-9 * expected);
    EXPECT_NEAR(cs.deposited + cs.offImage, expected, 1e-4 * expected);
}

TEST(FlareRaster, LostRaysNeverContributeAndEdgeCellsStayLocal) {
    // Lose a block of centre rays (with absurd weights) and a few corners: the lost centres add
    // nothing; cells with a lost corner are drawn around their own centre ray, never stretched to it.
    const ImageFrame frame{100, 100, 0.1};
    Synthetic s = affine(16, 0.2, 1, 0, 0, 1, 0.0, 0.0);
    double expected = 0.0;
    for (int j = 0; j < 16; ++j)
        for (int i = 0; i < 16; ++i) {
            RayResult& r = s.c[j * 16 + i];
            if (i < 4 && j < 4) {
                r.status = RayStatus::Blocked;
                r.weight = 1e9;
                r.sensorPoint = {1e6, 1e6, 0.0}; // far away: would streak if ever used
            } else {
                expected += 0.2 * 0.2;
            }
        }
    for (int i = 0; i < 5; ++i) {
        s.k[i].status = RayStatus::Blocked;
        s.k[i].sensorPoint = {-1e6, 0.0, 0.0};
    }
    std::vector<double> image(100 * 100, 0.0);
    RasterStats st;
    rasterizeCells(s.centres, s.c, s.k, 1.0, frame, image, st);
    EXPECT_NEAR(sum(image), expected, 1e-12);
    EXPECT_EQ(st.offImage, 0.0);
    // The blocked 4 x 4 corner of the grid (pixels 34..41 in x and y... mapped) stays dark.
    const glm::dvec2 corner = frame.sensorToPixel(-1.6 + 0.1, -1.6 + 0.1);
    EXPECT_EQ(image[static_cast<int>(corner.y) * 100 + static_cast<int>(corner.x)], 0.0);
}

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

// Exact area of a polygon inside the unit pixel [x, x + 1] x [y, y + 1], by clipping it against the
// pixel's four sides (an independent per-pixel computation, cost ~ area, to check the edge raster).
double pixelCoverage(std::vector<glm::dvec2> p, double x, double y) {
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
    double area = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
        area += p[i].x * p[(i + 1) % p.size()].y - p[(i + 1) % p.size()].x * p[i].y;
    return 0.5 * std::abs(area);
}

double polygonArea(const std::vector<glm::dvec2>& p) {
    double area = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
        area += p[i].x * p[(i + 1) % p.size()].y - p[(i + 1) % p.size()].x * p[i].y;
    return 0.5 * std::abs(area);
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
    std::uint64_t state = 12345;
    auto uniform = [&]() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>(state >> 11) * 0x1.0p-53;
    };
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

TEST(CoverageRaster, ReleaseGivesTheSameImageAsAddTo) {
    const ImageFrame frame{9, 5, 1.0};
    CoverageRaster raster(frame);
    RasterStats st;
    raster.polygon(std::vector<glm::dvec2>{{0.5, 0.5}, {8.2, 1.0}, {3.0, 4.9}}, 2.0, st);
    raster.point({4.3, 2.2}, 1.0, st);
    raster.pixel(8, 4, 0.5, st);
    std::vector<double> a(45, 0.0);
    raster.addTo(a);
    const std::vector<double> b = std::move(raster).release();
    ASSERT_EQ(b.size(), a.size());
    for (std::size_t p = 0; p < a.size(); ++p) EXPECT_EQ(a[p], b[p]);
    EXPECT_NEAR(sum(a), 3.5, 1e-12);
}
