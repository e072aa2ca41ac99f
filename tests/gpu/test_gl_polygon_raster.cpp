// The binned polygon raster (gpu::GlPolygonRaster: polygon_bins, bin_scan, polygon_tiles and
// polygon_image.comp) against the CPU's
// trace::CoverageRaster: random polygons of every kind the shaped renderer makes, of uniform and linear
// densities (triangles over five
// decades of size, clipped polygons of many vertices, slivers, polygons inside one pixel, points and
// segments, some over the frame's edges or far outside it) with energies over six decades; the
// image independent of the batching; and the whole shaped renderer on the Cooke triplet, its meshes
// cut on the CPU.

#include "ghosts/ghost_table.h"
#include "ghosts/shaped_ghosts.h"
#include "gpu/gl_context.h"
#include "gpu/gl_polygon_raster.h"
#include "optics/lens_loader.h"
#include "trace/flare_raster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "gl_test_support.h"

namespace ff::gpu {
namespace {

using testing::difference;

// Polygons in two channels, in pixels of a W x H frame.
std::vector<ghosts::ShapedPolygons> randomPolygons(int W, int H, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<ghosts::ShapedPolygons> out(2);
    auto energy = [&] { return std::pow(10.0, -6.0 * u(rng)); };
    auto centre = [&] { return glm::dvec2((1.2 * u(rng) - 0.1) * W, (1.2 * u(rng) - 0.1) * H); };
    for (int k = 0; k < 3000; ++k) {
        ghosts::ShapedPolygons& ps = out[static_cast<std::size_t>(k) % 2];
        std::vector<glm::dvec2> p;
        const glm::dvec2 c = centre();
        switch (k % 6) {
        case 0:
        case 1: { // a triangle of either orientation, 0.01 to 1000 pixels across
            const double size = std::pow(10.0, -2.0 + 5.0 * u(rng));
            for (int v = 0; v < 3; ++v) p.push_back(c + size * glm::dvec2(u(rng) - 0.5, u(rng) - 0.5));
            break;
        }
        case 2: { // a convex polygon of 4 to 12 vertices (a triangle clipped by apertures)
            const int n = 4 + static_cast<int>(u(rng) * 9);
            const double r = std::pow(10.0, -1.0 + 2.5 * u(rng)), turn = u(rng);
            const double sign = u(rng) < 0.5 ? 1.0 : -1.0;
            for (int v = 0; v < n; ++v) {
                const double a = sign * 2.0 * std::numbers::pi * (v + turn) / n;
                p.push_back(c + r * glm::dvec2(std::cos(a), std::sin(a)));
            }
            break;
        }
        case 3: { // a sliver: long, with a tiny area (a fold of the ghost's map)
            const glm::dvec2 d(20.0 * (u(rng) - 0.5), 20.0 * (u(rng) - 0.5));
            p = {c, c + d, c + 0.5 * d + glm::dvec2(1e-4 * u(rng), 1e-4 * u(rng))};
            break;
        }
        case 4: { // inside one pixel
            const glm::dvec2 o = glm::dvec2(std::floor(c.x), std::floor(c.y)) + glm::dvec2(0.1, 0.2);
            p = {o, o + glm::dvec2(0.5, 0.1), o + glm::dvec2(0.3, 0.6)};
            break;
        }
        default: // a point or a segment (no area): a bilinear splat
            p = {c, c + glm::dvec2(3.0 * u(rng), 0.0) * double(k % 12 == 5)};
            break;
        }
        if (k % 97 == 0) p[0] = {1e12, 5.0}; // far outside: nothing drawn
        // Every other polygon of area with a linear density: a gradient of up to 1.8 over its
        // extent, which keeps it positive.
        glm::dvec2 gradient(0.0);
        if (k % 2 == 0 && k % 6 < 4) {
            double extent = 0.0;
            for (const auto& v : p) extent = std::max(extent, std::abs(v.x - p[0].x) + std::abs(v.y - p[0].y));
            const double a = 2.0 * std::numbers::pi * u(rng);
            gradient = 0.9 * u(rng) / std::max(extent, 1e-9) * glm::dvec2(std::cos(a), std::sin(a));
        }
        ps.add(p.data(), p.size(), energy(), gradient);
    }
    return out;
}

std::vector<double> onCpu(const ghosts::ShapedPolygons& ps, const trace::ImageFrame& frame) {
    trace::CoverageRaster raster(frame);
    trace::RasterStats stats;
    std::vector<glm::dvec2> p;
    for (std::size_t i = 0; i < ps.polys.size(); ++i) {
        const auto& q = ps.polys[i];
        p.assign(ps.vertices.begin() + q.first, ps.vertices.begin() + q.first + q.count);
        raster.polygon(p, q.energy, ps.gradient(i), stats);
    }
    return std::move(raster).release();
}

double totalEnergy(const std::vector<ghosts::ShapedPolygons>& polys) {
    double e = 0.0;
    for (const auto& ps : polys) e += ps.energy;
    return e;
}

TEST(GlPolygonRaster, MatchesTheCpuCoverageRaster) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    const trace::ImageFrame frame{173, 97, 0.01}; // not multiples of the work group
    const auto polys = randomPolygons(frame.width, frame.height, 7);
    GlPolygonRaster gl(*context);
    gl.begin(frame, 2, totalEnergy(polys));
    for (std::size_t c = 0; c < 2; ++c) gl.draw(c, polys[c]);
    const auto image = gl.finish();
    ASSERT_EQ(image.size(), 2u);
    for (std::size_t c = 0; c < 2; ++c) {
        const auto d = difference(image[c], onCpu(polys[c], frame));
        // The edges in double as on the CPU; the pixels read back as float32 (6e-8).
        EXPECT_LE(d.relativeL2, 1e-6) << "channel " << c;
        EXPECT_LE(d.worst, 1e-6 * d.peak) << "channel " << c;
    }
}

// The raster draws 16 x 16-pixel tiles, each from the list of polygons that may touch it: polygons
// with vertices and edges on the tiles' sides, points splatted across them, pixels on either side,
// one polygon over the whole frame and 20 000 in one tile (far more than a work group) must give what
// the CPU's raster, which knows no tiles, gives.
TEST(GlPolygonRaster, TileSidesAndACrowdedTileMatchTheCpu) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    const trace::ImageFrame frame{70, 50, 0.01}; // 5 x 4 tiles, the last ones partial
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    ghosts::ShapedPolygons ps;
    auto add = [&](std::vector<glm::dvec2> p, glm::dvec2 g = glm::dvec2(0.0)) {
        ps.add(p.data(), p.size(), 0.1 + u(rng), g);
    };
    for (int i = 0; i <= 4; ++i)
        for (int j = 0; j <= 3; ++j) {
            const glm::dvec2 corner(16.0 * i, 16.0 * j);
            add({corner, corner + glm::dvec2(16.0, 0.0), corner + glm::dvec2(0.0, 16.0)}); // sides on the tiles'
            add({corner - glm::dvec2(3.0, 2.0), corner + glm::dvec2(5.0, 1.0), corner + glm::dvec2(1.0, 7.0)},
                glm::dvec2(0.05, -0.03));                                          // over a corner
            add({corner + glm::dvec2(-0.5, 0.5), corner + glm::dvec2(-0.5, 0.5)}); // splatted across
            add({corner + glm::dvec2(-0.9, 3.1), corner + glm::dvec2(-0.2, 3.2),
                 corner + glm::dvec2(-0.5, 3.8)}); // pixel left of a side
            add({corner + glm::dvec2(0.1, 3.1), corner + glm::dvec2(0.8, 3.2),
                 corner + glm::dvec2(0.5, 3.8)}); // pixel right of it
        }
    add({{-10.0, -10.0}, {90.0, -5.0}, {80.0, 70.0}, {-5.0, 60.0}}, glm::dvec2(0.004, 0.002)); // the whole frame
    for (int k = 0; k < 20000; ++k) {                                                          // tile (1, 1), crowded
        const glm::dvec2 c(16.0 + 16.0 * u(rng), 16.0 + 16.0 * u(rng));
        const double size = 0.2 + 3.0 * u(rng);
        add({c, c + size * glm::dvec2(u(rng), 0.3 * u(rng)), c + size * glm::dvec2(0.3 * u(rng), u(rng))});
    }
    GlPolygonRaster gl(*context);
    gl.begin(frame, 1, ps.energy);
    gl.draw(0, ps);
    const auto d = difference(gl.finish()[0], onCpu(ps, frame));
    EXPECT_LE(d.relativeL2, 1e-6);
    EXPECT_LE(d.worst, 1e-6 * d.peak);
}

// Integer sums do not depend on the order of the additions: any batching gives the same bytes.
TEST(GlPolygonRaster, SameBytesForAnyBatching) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    const trace::ImageFrame frame{120, 80, 0.01};
    const auto polys = randomPolygons(frame.width, frame.height, 3);
    std::vector<std::vector<double>> first;
    // The default batches; batches of 64 vertices; batches cut by a bound of 50 list entries.
    for (const auto& [batch, entries] :
         {std::pair{GlPolygonRaster::kDefaultBatch, GlPolygonRaster::kDefaultListEntries},
          std::pair{std::size_t(64), GlPolygonRaster::kDefaultListEntries},
          std::pair{GlPolygonRaster::kDefaultBatch, std::size_t(50)}}) {
        GlPolygonRaster gl(*context, batch, entries);
        gl.begin(frame, 2, totalEnergy(polys));
        for (std::size_t c = 0; c < 2; ++c) gl.draw(c, polys[c]);
        auto image = gl.finish();
        if (first.empty())
            first = std::move(image);
        else
            EXPECT_EQ(image, first) << "batch " << batch << ", list entries " << entries;
    }
}

// The shaped renderer drawing through the GL raster: the Cooke triplet's ghosts from two lights, one
// near a corner so that ghosts hang over the frame's edges.
TEST(GlPolygonRaster, ShapedGhostsMatchTheCpu) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    ghosts::TableSettings s;
    s.grid = 16;
    s.angles = 5;
    const ghosts::ShapedTable table =
        buildShapedTable(optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/cooke-triplet-50mm-f5.lens"), s);
    const trace::ImageFrame frame{192, 128, 36.0 / 192};
    std::vector<ghosts::ShapedLight> lights(2);
    lights[0].field = {0.4 * table.maxAngleDeg * std::numbers::pi / 180, 0.7};
    lights[1].field = {0.9 * table.maxAngleDeg * std::numbers::pi / 180, 2.6};
    lights[1].flux = {3.0, 2.0, 0.5};
    for (bool linear : {false, true}) { // uniform and linear elements
        SCOPED_TRACE(linear ? "linear elements" : "uniform elements");
        ghosts::ShapedRenderSettings settings;
        settings.linearDensity = linear;
        const ghosts::ShapedRender cpu = ghosts::renderShaped(table, lights, frame, settings);
        // The polygons cut on the CPU and sent (test_gl_mesh_cutter.cpp cuts them on the GPU).
        GlPolygonRaster raster(*context, GlPolygonRaster::kDefaultBatch, GlPolygonRaster::kDefaultListEntries, false);
        testing::expectShapedRendersMatch(ghosts::renderShaped(table, lights, frame, settings, &raster), cpu);
    }
}

} // namespace
} // namespace ff::gpu
