#include "core/units.h"
#include "ghosts/ghost_table.h"
#include "ghosts/shaped_ghosts.h"
#include "optics/lens_loader.h"
#include "trace/traced_flare.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "test_support.h"

using namespace ff;
using namespace ff::ghosts;

namespace {

// Relative L2 of a against b.
double relativeL2(const std::vector<double>& a, const std::vector<double>& b) {
    double d = 0.0, n = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) d += (a[i] - b[i]) * (a[i] - b[i]), n += b[i] * b[i];
    return std::sqrt(d / n);
}

double sum(const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0);
}

// An uncoated glass plate (n = 1.5, non-dispersive) behind a stop of 5 mm working radius: lit on
// the axis, its one ghost reflects off the back face, then the front face, at normal incidence,
// so it carries R^2 = 0.04^2 of the direct flux (the direct image keeps (1 - R)^2 of every ray,
// which the normalisation divides out), spread uniformly over the stop's opening imaged at unit
// magnification (the back face's 1e6 mm radius changes that by 3e-6).
std::string plateLens(int blades, double rotationDeg) {
    return "name: plate\nsensor: 36x24\naperture_blades: " + std::to_string(blades) +
           "\nblade_rotation: " + std::to_string(rotationDeg) +
           "\nsurfaces:\n  stop 10 1.0 0 5 0\n  0 5 1.5 0 12 0\n  1e6 50 1.0 0 12 0\n";
}

// Share of pixel (i, j) inside the polygon or circle, by 32 x 32 point sampling where an edge is near.
template <typename Inside>
std::vector<double> coverage(const trace::ImageFrame& frame, double reachMm, Inside&& inside) {
    std::vector<double> out(static_cast<std::size_t>(frame.width) * frame.height, 0.0);
    for (int j = 0; j < frame.height; ++j)
        for (int i = 0; i < frame.width; ++i) {
            const glm::dvec2 c = frame.pixelToSensor(i + 0.5, j + 0.5);
            if (std::hypot(c.x, c.y) > reachMm + frame.pitchMm) continue;
            int hits = 0;
            for (int b = 0; b < 32; ++b)
                for (int a = 0; a < 32; ++a) {
                    const glm::dvec2 p = frame.pixelToSensor(i + (a + 0.5) / 32, j + (b + 0.5) / 32);
                    hits += inside(p.x, p.y);
                }
            out[static_cast<std::size_t>(j) * frame.width + i] = hits / 1024.0;
        }
    return out;
}

// The plate's shaped table: 32 cells, 5 angles up to maxAngleDeg (0: the default field).
ShapedTable plateTable(int blades, double rotationDeg, double maxAngleDeg) {
    test::TempDir dir;
    test::writeFile(dir / "plate.lens", plateLens(blades, rotationDeg));
    TableSettings s;
    s.grid = 32;
    s.angles = 5;
    s.maxAngleDeg = maxAngleDeg;
    return buildShapedTable(optics::loadLens(dir / "plate.lens"), s);
}

// The Cooke triplet's shaped table: 16 cells, `angles` angles.
ShapedTable cookeTable(int angles) {
    TableSettings s;
    s.grid = 16;
    s.angles = angles;
    return buildShapedTable(optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/cooke-triplet-50mm-f5.lens"), s);
}

// The table's image of one light against the traced flare of the lens: within 0.05 relative L2 and
// the flux within 1 % per channel.
void expectShapedIsTraced(const optics::Lens& lens, const ShapedTable& table, const ShapedLight& light,
                          const trace::ImageFrame& frame) {
    const ShapedRender shaped = renderShaped(table, {light}, frame);
    trace::TracedFlareOptions o;
    o.frame = frame;
    o.field = light.field;
    const trace::TracedFlare traced = trace::renderTracedFlare(lens, o);
    for (int c = 0; c < 3; ++c) {
        std::vector<double> ref(shaped.channel[c].size());
        for (std::size_t p = 0; p < ref.size(); ++p) ref[p] = traced.rgb[p * 3 + c];
        EXPECT_LT(relativeL2(shaped.channel[c], ref), 0.05) << "channel " << c;
        EXPECT_NEAR(sum(shaped.channel[c]) / sum(ref), 1.0, 0.01) << "channel " << c;
    }
}

} // namespace

TEST(ShapedPolygons, KeepsEveryPolygonsGradientFromTheFirst) {
    // Uniform polygons store no gradients; once one has a gradient, every polygon has its own,
    // the first polygon's included when it is the one.
    const glm::dvec2 tri[3] = {{0.0, 0.0}, {4.0, 0.0}, {0.0, 4.0}};
    ShapedPolygons first;
    first.add(tri, 3, 1.0, {0.25, -0.5});
    first.add(tri, 3, 1.0);
    EXPECT_EQ(first.gradient(0), glm::dvec2(0.25, -0.5));
    EXPECT_EQ(first.gradient(1), glm::dvec2(0.0));
    ShapedPolygons later;
    later.add(tri, 3, 1.0);
    EXPECT_TRUE(later.gradients.empty());
    later.add(tri, 3, 1.0, {0.125, 0.0});
    EXPECT_EQ(later.gradient(0), glm::dvec2(0.0));
    EXPECT_EQ(later.gradient(1), glm::dvec2(0.125, 0.0));
}

TEST(ShapedGhosts, AGlassPlateGhostIsAUniformDiscOfKnownIrradiance) {
    const ShapedTable table = plateTable(0, 0.0, 0.0);
    ASSERT_EQ(table.ghosts.size(), 1u);
    const trace::ImageFrame frame{240, 160, 36.0 / 240};
    const ShapedRender r = renderShaped(table, {ShapedLight{}}, frame);
    const double R2 = 0.04 * 0.04, radius = 5.0;
    std::vector<double> expected =
        coverage(frame, radius, [&](double x, double y) { return std::hypot(x, y) <= radius; });
    const double pixelShare = frame.pitchMm * frame.pitchMm / (std::numbers::pi * radius * radius);
    for (double& v : expected) v *= R2 * pixelShare;
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(sum(r.channel[c]) / R2, 1.0, 2e-3) << "channel " << c;
        EXPECT_LT(relativeL2(r.channel[c], expected), 0.02) << "channel " << c;
    }
    // Its triangles cover the disc once in each channel: per pixel, a third of them over its area.
    const double discPx = std::numbers::pi * radius * radius / (frame.pitchMm * frame.pitchMm);
    EXPECT_NEAR(r.trianglesPerPixel, static_cast<double>(r.triangles) / 3.0 / discPx, 0.01 * r.trianglesPerPixel);
    EXPECT_NEAR(r.mostTrianglesPerPixel, r.trianglesPerPixel, 1e-3 * r.trianglesPerPixel);
}

// Linear elements (ShapedRenderSettings::linearDensity) shape each triangle's density and keep its
// flux: the plate's ghost (a constant Jacobian and weight) stays the uniform disc, and the Cooke
// triplet's ghosts between table angles keep every channel's flux to rounding while their pixels move.
TEST(ShapedGhosts, LinearElementsKeepTheFluxOfEveryTriangle) {
    {
        const ShapedTable table = plateTable(0, 0.0, 0.0);
        const trace::ImageFrame frame{240, 160, 36.0 / 240};
        ShapedRenderSettings uniform, linear;
        uniform.linearDensity = false;
        linear.linearDensity = true;
        const ShapedRender flat = renderShaped(table, {ShapedLight{}}, frame, uniform);
        const ShapedRender r = renderShaped(table, {ShapedLight{}}, frame, linear);
        // Equal to the float rounding of the stored mesh (its Jacobian constant to ~1e-7).
        for (int c = 0; c < 3; ++c) EXPECT_LT(relativeL2(r.channel[c], flat.channel[c]), 1e-6) << "channel " << c;
    }
    TableSettings s;
    s.grid = 16;
    s.angles = 5;
    const ShapedTable table =
        buildShapedTable(optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/cooke-triplet-50mm-f5.lens"), s);
    const trace::ImageFrame frame{240, 160, 36.0 / 240};
    ShapedLight light;
    light.field = {0.55 * table.maxAngleDeg * std::numbers::pi / 180, 0.8};
    // The same cells for both: the irradiance's part of the subdivision depends on the elements.
    ShapedRenderSettings uniform;
    uniform.linearDensity = false;
    uniform.irradianceError = std::numeric_limits<double>::infinity();
    ShapedRenderSettings linear = uniform;
    linear.linearDensity = true;
    const ShapedRender flat = renderShaped(table, {light}, frame, uniform);
    const ShapedRender r = renderShaped(table, {light}, frame, linear);
    EXPECT_EQ(r.triangles, flat.triangles);
    EXPECT_NEAR(r.deposited + r.offImage, flat.deposited + flat.offImage, 1e-9 * (flat.deposited + flat.offImage));
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(sum(r.channel[c]), sum(flat.channel[c]), 1e-3 * sum(flat.channel[c])) << "channel " << c;
        const double moved = relativeL2(r.channel[c], flat.channel[c]);
        EXPECT_GT(moved, 1e-4) << "channel " << c; // the densities are not uniform
        EXPECT_LT(moved, 0.05) << "channel " << c;
    }
}

// The subdivision for the irradiance is stated in pixels (docs/ghost-table.md, "Subdivision in
// pixels"): on the Cooke triplet's ghosts it splits cells that span pixels, and never a cell whose
// sub-cells would be narrower than a quarter pixel — on a frame whose pixels are 8 times the widest
// cell of any ghost at any table angle (the span of its diagonals along x and y, which the
// interpolation between angles does not double), it splits none (the other rules held off: their
// tolerances at 1e9 pixels).
TEST(ShapedGhosts, TheIrradianceSplitsCellsThatSpanPixelsAndNoneBelowAQuarterPixel) {
    const ShapedTable table = cookeTable(5);
    ShapedLight light;
    light.field = {0.55 * table.maxAngleDeg * std::numbers::pi / 180, 0.8};
    ShapedRenderSettings none;
    none.flatnessPx = none.maxFlatnessPx = 1e9;
    none.subcellPx = 1e9;
    none.irradianceError = std::numeric_limits<double>::infinity();
    ShapedRenderSettings split = none;
    split.irradianceError = 0.002;
    double widest = 0.0; // mm
    for (const ShapedGhost& gh : table.ghosts)
        for (const auto& byAngle : gh.meshes)
            for (const ShapedMesh& m : byAngle) {
                if (m.data.empty()) continue;
                auto at = [&](int i, int j) { return &m.data[(std::size_t(j) * (gh.grid + 1) + i) * gh.stride()]; };
                for (int j = 0; j < gh.grid; ++j)
                    for (int i = 0; i < gh.grid; ++i) {
                        const float *p = at(i, j), *q = at(i + 1, j), *r = at(i, j + 1), *u = at(i + 1, j + 1);
                        const double span = std::max({std::abs(u[0] - p[0]), std::abs(q[0] - r[0]),
                                                      std::abs(u[1] - p[1]), std::abs(q[1] - r[1])});
                        if (std::isfinite(span)) widest = std::max(widest, span);
                    }
            }
    ASSERT_GT(widest, 0.0);
    const trace::ImageFrame fine{240, 160, 36.0 / 240}, coarse{2, 2, 8.0 * widest};
    EXPECT_GT(renderShaped(table, {light}, fine, split).triangles, renderShaped(table, {light}, fine, none).triangles);
    const ShapedRender a = renderShaped(table, {light}, coarse, split), b = renderShaped(table, {light}, coarse, none);
    EXPECT_GT(b.triangles, 0u);
    EXPECT_EQ(a.triangles, b.triangles);
}

// The same plate with a 6-blade iris turned by 10 degrees and a light off the axis at azimuth 40
// degrees: the ghost is the iris itself (unit magnification; the tilt of the beam shifts it, but
// the plate is flat, so its shape is the iris's whatever the light's azimuth) — a hexagon that keeps
// the lens's orientation, not one turned with the light. Its area equals the circle of the working
// radius (trace/aperture.h), so the irradiance is the disc's.
TEST(ShapedGhosts, ThePolygonIrisKeepsTheLensOrientationForAnyAzimuth) {
    const ShapedTable table = plateTable(6, 10.0, 4.0);
    ASSERT_EQ(table.ghosts.size(), 1u);
    const trace::ImageFrame frame{240, 160, 36.0 / 240};
    const double radius = 5.0, sector = std::numbers::pi / 3;
    const double circum = radius * std::sqrt(2.0 * std::numbers::pi / (6 * std::sin(sector)));
    const double apothem = circum * std::cos(0.5 * sector), rot = 10.0 * std::numbers::pi / 180;
    for (double azDeg : {0.0, 40.0}) {
        // On the axis, then at 2 degrees: the ghost's centre moves with the light (found from the
        // rendered image's centroid, so that the test checks the shape, not where the table puts it).
        for (double angleDeg : {0.0, 2.0}) {
            ShapedLight light;
            light.field = {angleDeg * std::numbers::pi / 180, azDeg * std::numbers::pi / 180};
            const ShapedRender r = renderShaped(table, {light}, frame);
            const auto& g = r.channel[1];
            double cx = 0.0, cy = 0.0, total = sum(g);
            for (int j = 0; j < frame.height; ++j)
                for (int i = 0; i < frame.width; ++i) {
                    const glm::dvec2 c = frame.pixelToSensor(i + 0.5, j + 0.5);
                    cx += c.x * g[static_cast<std::size_t>(j) * frame.width + i] / total;
                    cy += c.y * g[static_cast<std::size_t>(j) * frame.width + i] / total;
                }
            std::vector<double> expected = coverage(frame, std::hypot(cx, cy) + circum, [&](double x, double y) {
                for (int k = 0; k < 6; ++k) {
                    const double phi = rot + (k + 0.5) * sector;
                    if ((x - cx) * std::cos(phi) + (y - cy) * std::sin(phi) > apothem) return false;
                }
                return true;
            });
            const double norm = total / sum(expected);
            for (double& v : expected) v *= norm;
            EXPECT_LT(relativeL2(g, expected), 0.03) << "azimuth " << azDeg << ", angle " << angleDeg;
        }
    }
}

// Against the traced renderer (Embree, adaptively refined pupil grids: an independent path), the
// Cooke triplet with its stop made a 7-blade iris, one light mid-field at an azimuth that is not a
// multiple of the blades' symmetry, between two of the table's angles: the image within 0.05
// relative L2 and the flux within 1 % per channel.
TEST(ShapedGhosts, MatchesTheTracedFlareBetweenTableAngles) {
    test::TempDir dir;
    std::string text = test::readFile(std::string(FF_SOURCE_DIR) + "/lenses/cooke-triplet-50mm-f5.lens");
    text.replace(text.find("sensor: 36x24"), 13, "sensor: 36x24\naperture_blades: 7\nblade_rotation: 5");
    test::writeFile(dir / "cooke7.lens", text);
    const optics::Lens lens = optics::loadLens(dir / "cooke7.lens");
    TableSettings s;
    s.grid = 32; // the default angles (25): at 9 the flux is 2-3 % off across vignetting onsets
    const ShapedTable table = buildShapedTable(lens, s);
    const trace::ImageFrame frame{320, 214, 36.0 / 320};
    ShapedLight light;
    light.field = {0.63 * table.maxAngleDeg * std::numbers::pi / 180, 1.1};
    expectShapedIsTraced(lens, table, light, frame);
}

// The bundled GRIN rod's one ghost is cut inside the rod by its barrel, where no surface's aperture
// is: the barrel's margin (the largest radius the curved path reaches) cuts the mesh as a surface's
// does, so at a table angle the shaped ghost is the traced one.
TEST(ShapedGhosts, TheBarrelOfAGradedElementCutsTheGhostAsTheTracedFlareDoes) {
    const optics::Lens lens = optics::loadLens(test::lensPath("grin-rod-1.8mm-0.23-pitch.lens"));
    TableSettings s;
    s.grid = 32;
    s.angles = 9;
    const ShapedTable table = buildShapedTable(lens, s);
    ASSERT_EQ(table.ghosts.size(), 1u);
    const trace::ImageFrame frame{240, 180, 1.0 / 240};
    ShapedLight light;
    light.field = {0.5 * table.maxAngleDeg * std::numbers::pi / 180, 0.3};
    expectShapedIsTraced(lens, table, light, frame);
}

// Culling drops the faintest ghosts of a light while they hold at most the given share of its ghost
// flux: the flux drawn (in and out of the frame) loses no more than that share.
TEST(ShapedGhosts, CullingDropsAtMostTheGivenShareOfTheGhostFlux) {
    const ShapedTable table = cookeTable(3);
    const trace::ImageFrame frame{160, 107, 36.0 / 160};
    ShapedRenderSettings all, culled;
    all.cullShare = 0.0;
    culled.cullShare = 0.05;
    const ShapedRender a = renderShaped(table, {ShapedLight{}}, frame, all);
    const ShapedRender b = renderShaped(table, {ShapedLight{}}, frame, culled);
    EXPECT_EQ(a.culled, 0u);
    EXPECT_GT(b.culled, 0u);
    EXPECT_LE(b.culledShare, 0.05);
    const double fa = a.deposited + a.offImage, fb = b.deposited + b.offImage;
    EXPECT_LE(fb, fa);
    // The share is judged on the table's flux estimates (its meshes' cells as flat triangles), the
    // drawing subdivides them bicubically: 0.5 % apart at most on this lens.
    EXPECT_GE(fb, (1.0 - 0.05 - 0.005) * fa);
}

// A light exactly at a table angle draws that angle's meshes as they are: without subdivision the
// drawn flux is the meshes' own (their cells as flat triangles), whatever the rays lost at the next
// angle, at every angle of a lens that vignettes (the Cooke triplet: rays come and go between
// angles).
TEST(ShapedGhosts, ALightAtATableAngleDrawsThatAnglesFlux) {
    const ShapedTable table = cookeTable(9);
    const trace::ImageFrame frame{64, 43, 36.0 / 64};
    ShapedRenderSettings flat;
    flat.cullShare = 0.0;
    flat.maxSubdivision = 1;
    for (int a = 0; a + 1 < table.angles(); ++a) {
        ShapedLight light;
        light.field = {a * table.angleStep() * std::numbers::pi / 180.0, 0.0};
        const ShapedRender r = renderShaped(table, {light}, frame, flat);
        double expected = 0.0;
        for (const ShapedGhost& g : table.ghosts)
            for (std::size_t w = 0; w < 3; ++w) expected += g.meshes[w][static_cast<std::size_t>(a)].flux;
        EXPECT_NEAR((r.deposited + r.offImage) / expected, 1.0, 1e-5) << "angle " << a;
    }
}

// The fitted entry of the glass plate's ghost against its known image: on the axis a uniform disc
// of the stop's working radius r = 5 mm carrying R^2 of the direct flux, so centroid 0 and sigma r =
// sigma t = m r / 2 (a uniform disc's second moment per axis is r^2 / 4). m is the ghost's
// magnification of the collimated beam by the back face (radius R = 1e6 mm, convex towards the
// light): reflected inside the glass it diverges at 2h/R; 5 mm back to the front face, 5 mm forward
// again (h (1 + 20/R)); out through the back face at a slope of (1.5 x 2h + 0.5 h) / R = 3.5 h / R,
// then 50 mm to the sensor: m = 1 + (20 + 175) / R. With a 6-blade iris of the same area, a regular
// hexagon of apothem a and half-side s: per axis sigma^2 = m^2 (a^2 / 4 + s^2 / 12) (each of its six
// triangles about the centre has a polar moment of s a^3 / 2 + s^3 a / 6 over its area s a; half of
// that per axis). The circle's edge is cut by chords of the mesh's 32 cells (sigma within 0.5 %); the
// blades exactly (within 1e-6).
TEST(ShapedGhosts, TheFittedEntryOfAPlateGhostHasItsKnownFluxAndMoments) {
    const double R2 = 0.04 * 0.04, radius = 5.0, m = 1.0 + 195.0 / 1e6;
    const ShapedTable disc = plateTable(0, 0.0, 0.0);
    ASSERT_EQ(disc.fitted.ghosts.size(), 1u);
    for (std::size_t w = 0; w < disc.wavelengthsNm.size(); ++w) {
        const TableEntry& e = disc.fitted.ghosts[0].entries[w][0];
        EXPECT_NEAR(e.flux / R2, 1.0, 2e-3);
        EXPECT_NEAR(e.centroidY, 0.0, 1e-6);
        EXPECT_NEAR(e.sigmaR / (0.5 * m * radius), 1.0, 5e-3);
        EXPECT_NEAR(e.sigmaT / (0.5 * m * radius), 1.0, 5e-3);
        EXPECT_NEAR(e.surviving, 1.0, 5e-3); // the whole pupil passes
    }
    const ShapedTable hexagon = plateTable(6, 10.0, 4.0);
    ASSERT_EQ(hexagon.fitted.ghosts.size(), 1u);
    const double sector = std::numbers::pi / 3;
    const double circum = radius * std::sqrt(2.0 * std::numbers::pi / (6 * std::sin(sector)));
    const double a = circum * std::cos(0.5 * sector), s = circum * std::sin(0.5 * sector);
    const double sigma = m * std::sqrt(a * a / 4 + s * s / 12);
    const TableEntry& e = hexagon.fitted.ghosts[0].entries[1][0];
    EXPECT_NEAR(e.flux / R2, 1.0, 2e-3);
    EXPECT_NEAR(e.sigmaR / sigma, 1.0, 1e-6);
    EXPECT_NEAR(e.sigmaT / sigma, 1.0, 1e-6);
}

// The entry's flux is the flux the shaped renderer draws for that ghost alone (in and out of the
// frame), a light exactly at the table's angle drawn without subdivision (the same clipped
// triangles), for every ghost of the Cooke triplet at every angle and wavelength: exact up to
// rounding, where all of the ghost's light lands within twice the sensor's half-diagonal (the
// light the table counts).
TEST(ShapedGhosts, EachFittedEntryHoldsTheFluxTheRendererDraws) {
    const ShapedTable table = cookeTable(5);
    ShapedRenderSettings flat;
    flat.cullShare = 0.0;
    flat.flatnessPx = flat.maxFlatnessPx = 1e9;
    flat.subcellPx = 1e9;
    flat.irradianceError = 1e9;
    const double reach = std::hypot(table.sensorSizeMm.first, table.sensorSizeMm.second);
    const trace::ImageFrame frame{200, 200, reach / 100}; // holds the circle the table counts
    double worst = 0.0;
    std::size_t compared = 0;
    for (std::size_t g = 0; g < table.ghosts.size(); ++g) {
        ShapedTable one = table;
        one.ghosts = {table.ghosts[g]};
        for (int a = 0; a < table.angles(); ++a)
            for (std::size_t w = 0; w < 3; ++w) {
                ShapedLight light;
                light.field = {degToRad(table.angleStep() * a), 0.0};
                light.flux = {0.0, 0.0, 0.0};
                light.flux[w] = 1.0;
                const ShapedRender r = renderShaped(one, {light}, frame, flat);
                if (r.offImage > 0.0) continue; // light beyond the frame: not all counted by the table
                const double drawn = sum(r.channel[w]);
                const double entry = table.fitted.ghosts[g].entries[w][static_cast<std::size_t>(a)].flux;
                if (entry <= 0.0 && drawn <= 0.0) continue;
                worst = std::max(worst, std::abs(entry - drawn) / std::max(entry, drawn));
                ++compared;
            }
    }
    EXPECT_GT(compared, 60u);
    EXPECT_LT(worst, 1e-9);
}
