// The shaped ghosts' meshes cut on the GPU (gpu::GlMeshCutter: mesh_place.comp, mesh_cells.comp)
// against ghosts::renderShaped's own cutting on the CPU, both drawn exactly (the GPU's binned raster,
// trace::CoverageRaster): the same triangles, the images within float precision, the same energy
// off the frame; a circular and a bladed iris, uniform and linear elements, lights between and at
// the table's angles, turned and over the frame's edges; the same bytes run after run.

#include "ghosts/ghost_table.h"
#include "ghosts/shaped_ghosts.h"
#include "gpu/gl_context.h"
#include "gpu/gl_mesh_cutter.h"
#include "gpu/gl_polygon_raster.h"
#include "optics/lens_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gl_test_support.h"

namespace ff::gpu {
namespace {

const ghosts::ShapedTable& cookeTable() {
    static const ghosts::ShapedTable table = [] {
        ghosts::TableSettings s;
        s.grid = 16;
        s.angles = 5;
        return ghosts::buildShapedTable(
            optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/cooke-triplet-50mm-f5.lens"), s);
    }();
    return table;
}

std::vector<ghosts::ShapedLight> lightsOver(const ghosts::ShapedTable& table) {
    const double deg = std::numbers::pi / 180.0;
    std::vector<ghosts::ShapedLight> lights(4);
    lights[0].field = {0.4 * table.maxAngleDeg * deg, 0.7};
    lights[1].field = {0.9 * table.maxAngleDeg * deg, 2.6}; // near a corner: ghosts over the edges
    lights[1].flux = {3.0, 2.0, 0.5};
    lights[2].field = {0.5 * table.maxAngleDeg * deg, -1.9}; // on a table angle
    lights[3].field = {0.0, 0.0};                            // on the axis
    lights[3].flux = {0.2, 0.3, 0.4};
    return lights;
}

// Tolerances ten times the defaults: every rule of the subdivision still acts, on fewer triangles
// (llvmpipe runs the shaders' doubles slowly).
ghosts::ShapedRenderSettings coarse() {
    ghosts::ShapedRenderSettings s;
    s.flatnessPx *= 10.0;
    s.irradianceError *= 10.0;
    return s;
}

TEST(GlMeshCutter, CutsWhatTheCpuCuts) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    ghosts::ShapedTable table = cookeTable();
    const trace::ImageFrame frame{192, 128, 36.0 / 192};
    const auto lights = lightsOver(table);
    GlPolygonRaster raster(*context);
    for (int blades : {0, 6}) {
        table.iris = trace::Iris(blades, 0.3, table.iris.radius);
        ASSERT_TRUE(raster.cutsMeshes(table));
        for (bool linear : {false, true}) {
            SCOPED_TRACE(std::string(blades ? "6 blades, " : "circular iris, ") + (linear ? "linear" : "uniform"));
            ghosts::ShapedRenderSettings settings = coarse();
            settings.linearDensity = linear;
            const ghosts::ShapedRender cpu = ghosts::renderShaped(table, lights, frame, settings);
            const ghosts::ShapedRender gl = ghosts::renderShaped(table, lights, frame, settings, &raster);
            EXPECT_GT(cpu.triangles, cpu.drawn * 3 * 2 * 16 * 16); // subdivided: more than the meshes' triangles
            EXPECT_NEAR(gl.trianglesPerPixel, cpu.trianglesPerPixel, 1e-9 * cpu.trianglesPerPixel);
            testing::expectShapedRendersMatch(gl, cpu);
        }
    }
}

TEST(GlMeshCutter, DrawsTheHybridsGridAsTheCpuDoes) {
    // The instances the split sends to the Fourier series are cut on the grid of 4-pixel cells
    // (decimated meshes, the edges' own tolerance, small polygons splatted), on the GPU as on the CPU.
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    const ghosts::ShapedTable& table = cookeTable();
    const trace::ImageFrame frame{192, 128, 36.0 / 192};
    const auto lights = lightsOver(table);
    ghosts::ShapedRenderSettings settings = coarse();
    settings.gridError = 0.05;
    settings.grid = {4, 64, 48, -32.0, -32.0};
    const ghosts::ShapedRender cpu = ghosts::renderShaped(table, lights, frame, settings);
    GlPolygonRaster raster(*context);
    const ghosts::ShapedRender gl = ghosts::renderShaped(table, lights, frame, settings, &raster);
    ASSERT_GT(cpu.gridded, 0u);
    ASSERT_GT(cpu.drawn, cpu.gridded); // some drawn directly too
    EXPECT_EQ(gl.gridded, cpu.gridded);
    EXPECT_EQ(gl.gridTriangles, cpu.gridTriangles);
    testing::expectShapedRendersMatch(gl, cpu);
    testing::expectChannelsNear(gl.grid, cpu.grid, 1e-6, "grid channel");
}

TEST(GlMeshCutter, SameBytesRunAfterRun) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    const ghosts::ShapedTable& table = cookeTable();
    const trace::ImageFrame frame{160, 96, 36.0 / 160};
    const std::vector<ghosts::ShapedLight> lights{lightsOver(table)[1]};
    GlPolygonRaster a(*context), b(*context, 64, 4096); // b's lists split the cut polygons into batches
    const ghosts::ShapedRender first = ghosts::renderShaped(table, lights, frame, coarse(), &a);
    const ghosts::ShapedRender again = ghosts::renderShaped(table, lights, frame, coarse(), &a);
    const ghosts::ShapedRender split = ghosts::renderShaped(table, lights, frame, coarse(), &b);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(again.channel[c], first.channel[c]) << "channel " << c;
        EXPECT_EQ(split.channel[c], first.channel[c]) << "channel " << c;
    }
    EXPECT_EQ(again.offImage, first.offImage);
}

TEST(GlMeshCutter, LeavesTwoDimensionalTablesToTheCpu) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    ghosts::ShapedTable table = cookeTable();
    EXPECT_TRUE(GlMeshCutter::takes(table));
    table.fieldGrid = {2, 2, 0.1, 0.1};
    EXPECT_FALSE(GlMeshCutter::takes(table));
    GlPolygonRaster raster(*context, GlPolygonRaster::kDefaultBatch, GlPolygonRaster::kDefaultListEntries, false);
    EXPECT_FALSE(raster.cutsMeshes(cookeTable()));
}

} // namespace
} // namespace ff::gpu
