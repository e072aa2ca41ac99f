// Shaped ghosts of anamorphic lenses: the two-dimensional table (shaped_ghosts.h) against a
// cylinder's ghost in closed form, against the mirror symmetry that lets it hold one quadrant, through
// the cache, and against the traced flare of the bundled 2x anamorphic.

#include "core/units.h"
#include "ghosts/ghost_table.h"
#include "ghosts/shaped_cache.h"
#include "ghosts/shaped_ghosts.h"
#include "optics/lens_loader.h"
#include "trace/sensor.h"
#include "trace/traced_flare.h"
#include "trace/uniform_ellipse.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <numeric>

#include "test_support.h"

using namespace ff;
using namespace ff::ghosts;

namespace {

double relativeL2(const std::vector<double>& a, const std::vector<double>& b) {
    double d = 0.0, n = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) d += (a[i] - b[i]) * (a[i] - b[i]), n += b[i] * b[i];
    return std::sqrt(d / n);
}

double sum(const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0);
}

// The field of tangents (tx, ty): its direct image on the side of (tx, ty) (ShapedTable::FieldGrid).
trace::Field tangentField(double tx, double ty) {
    return {std::atan(std::hypot(tx, ty)), std::atan2(-tx, ty)};
}

// An uncoated plate (n = 1.5, 5 mm) behind a stop of 5 mm working radius, its back face a biconic of
// Rx = 400 mm and Ry = 1e6 mm, the sensor 50 mm behind it: one ghost (tests/trace's cylinder plate).
// `iris`: the stop's blades line ("" for a round stop).
optics::Lens cylinderPlate(const test::TempDir& dir, const std::string& iris = "") {
    test::writeFile(dir / "cylinder.lens", "name: cylinder plate\nsensor: 36x24\n" + iris +
                                               "surfaces:\n"
                                               "  stop 10 1.0 0 5 0\n"
                                               "  0 5 1.5 0 12 0\n"
                                               "  1e6 50 1.0 0 12 0 biconic=400\n");
    return optics::loadLens(dir / "cylinder.lens");
}

ShapedTable smallTable(const optics::Lens& lens) {
    TableSettings s;
    s.grid = 32;
    s.angles = 9;
    return buildShapedTable(lens, s);
}

} // namespace

// On the axis the cylinder plate's ghost is the stop's disc scaled by each section's paraxial
// magnification, m = 1 + 4tc + Dc(3 + 0.5(1 + 4tc)) (m_x = 1.4906, m_y = 1.0000; derived in
// tests/trace/test_anamorphic_trace.cpp), holding R^2 = 0.04^2 of the direct flux uniformly. The
// two-dimensional table draws it so, within 2 % relative L2 (the rim's chords) and 0.5 % in flux.
TEST(AnamorphicShaped, ACylindricalPlatesGhostIsTheEllipseOfItsParaxialMagnifications) {
    test::TempDir dir;
    const optics::Lens lens = cylinderPlate(dir);
    const ShapedTable table = smallTable(lens);
    ASSERT_TRUE(table.twoDimensional());
    EXPECT_TRUE(table.fitted.ghosts.empty()); // no fits without rotational symmetry
    const double t = 5.0, D = 50.0, r = 5.0, R = 0.04;
    const auto m = [&](double c) { return 1.0 + 4.0 * t * c + D * c * (3.0 + 0.5 * (1.0 + 4.0 * t * c)); };
    const trace::ImageFrame frame{480, 320, 36.0 / 480};
    ShapedRenderSettings settings;
    settings.cullShare = 0.0;
    const ShapedRender shaped = renderShaped(table, {{tangentField(0.0, 0.0), {1.0, 1.0, 1.0}}}, frame, settings);
    const std::vector<double> expected = test::uniformEllipse(frame, r * m(1.0 / 400.0), r * m(1e-6), R * R);
    for (int c = 0; c < 3; ++c) {
        EXPECT_LT(relativeL2(shaped.channel[c], expected), 0.02) << "channel " << c;
        EXPECT_NEAR(sum(shaped.channel[c]), R * R, 5e-3 * R * R) << "channel " << c;
    }
}

// The lens is symmetric about the x-z and y-z planes, its iris need not be: a light at (-tx, ty) sees
// the x-mirror of what a light at (tx, ty) sees through the lens with the iris mirrored. A blade
// iris at rotation rho has its corners at rho + 2 pi k / n; mirrored in x (phi -> pi - phi) at
// pi - rho, in y (phi -> -phi) at -rho. The table holds one quadrant: its images in the others must
// be these mirror images, the iris's corners included (a 5-blade iris at 10 deg has no mirror line
// along either axis), to the rounding of the polygons' single-precision pixel coordinates (a few
// 1e-5 px at 360 px: 1e-5 relative L2).
TEST(AnamorphicShaped, ALightInAnotherQuadrantSeesTheMirrorImage) {
    test::TempDir dir;
    const double rho = degToRad(10.0);
    const ShapedTable table = smallTable(cylinderPlate(dir, "aperture_blades: 5\nblade_rotation: 10\n"));
    ASSERT_EQ(table.iris.blades, 5);
    const trace::ImageFrame frame{360, 240, 0.1};
    ShapedRenderSettings settings;
    settings.cullShare = 0.0;
    const double tx = 0.05, ty = 0.03;
    auto render = [&](const ShapedTable& t, double x, double y) {
        return renderShaped(t, {{tangentField(x, y), {1.0, 1.0, 1.0}}}, frame, settings);
    };
    auto withIris = [&](double rotation) {
        ShapedTable t = table;
        t.iris = trace::Iris(table.iris.blades, rotation, table.iris.radius);
        return t;
    };
    const ShapedRender here = render(table, tx, ty);
    const ShapedRender mirrorX = render(withIris(std::numbers::pi - rho), tx, ty);
    const ShapedRender mirrorY = render(withIris(-rho), tx, ty);
    const ShapedRender left = render(table, -tx, ty), below = render(table, tx, -ty);
    const auto flipped = [&](const std::vector<double>& v, bool inX) {
        std::vector<double> out(v.size());
        for (int j = 0; j < frame.height; ++j)
            for (int i = 0; i < frame.width; ++i) {
                const int si = inX ? frame.width - 1 - i : i, sj = inX ? j : frame.height - 1 - j;
                out[static_cast<std::size_t>(j) * frame.width + i] = v[static_cast<std::size_t>(sj) * frame.width + si];
            }
        return out;
    };
    for (int c = 0; c < 3; ++c) {
        ASSERT_GT(sum(here.channel[c]), 0.0);
        EXPECT_LT(relativeL2(left.channel[c], flipped(mirrorX.channel[c], true)), 1e-5) << "channel " << c;
        EXPECT_LT(relativeL2(below.channel[c], flipped(mirrorY.channel[c], false)), 1e-5) << "channel " << c;
        // Not a test that cannot fail: the iris's orientation shows.
        EXPECT_GT(relativeL2(left.channel[c], flipped(here.channel[c], true)), 1e-3) << "channel " << c;
    }
}

// The cache keeps a two-dimensional table: its field grid, every field's mesh (within the 16-bit
// quantisation), and no fits.
TEST(AnamorphicShaped, TheCacheKeepsTheFieldGrid) {
    test::TempDir dir;
    const ShapedTable table = smallTable(cylinderPlate(dir));
    std::string key;
    const ShapedTable back = shapedTableFromBytes(shapedTableToBytes(table, "k"), "entry", key);
    EXPECT_EQ(key, "k");
    ASSERT_TRUE(back.twoDimensional());
    EXPECT_EQ(back.fieldGrid.x, table.fieldGrid.x);
    EXPECT_EQ(back.fieldGrid.y, table.fieldGrid.y);
    EXPECT_EQ(back.fieldGrid.maxTanX, table.fieldGrid.maxTanX);
    EXPECT_EQ(back.fieldGrid.maxTanY, table.fieldGrid.maxTanY);
    EXPECT_TRUE(back.fitted.ghosts.empty());
    ASSERT_EQ(back.ghosts.size(), table.ghosts.size());
    ASSERT_EQ(back.angles(), table.fieldGrid.x * table.fieldGrid.y);
    const ShapedGhost &a = table.ghosts[0], &b = back.ghosts[0];
    for (std::size_t f = 0; f < a.meshes[1].size(); ++f) {
        ASSERT_EQ(a.meshes[1][f].data.size(), b.meshes[1][f].data.size());
        for (std::size_t k = 0; k < a.meshes[1][f].data.size(); k += a.stride())
            if (!std::isnan(a.meshes[1][f].data[k])) {
                EXPECT_NEAR(b.meshes[1][f].data[k], a.meshes[1][f].data[k], 1e-3) << "field " << f;
            }
    }
}

// The bundled 2x anamorphic's table against its traced flare (the adaptive traced renderer: an
// independent path) at the frame's centre, on its vertical axis, off both axes and towards a corner,
// where vignetting dims the light steeply: the flux within 4 % per channel (8 % towards the corner),
// and at the centre the image within 0.10 relative L2 (a frame of odd height keeps the cylinders'
// line focus, at the light's height, inside one row). Fields spaced twice as far apart put 1.2 times
// the traced flux towards the corner. The 1 % and 0.03 anamorphic ghosts are to reach are not met
// yet (docs/anamorphic.md: the measurements and the causes).
TEST(AnamorphicShaped, TheBundledAnamorphicsTableKeepsTheTracedFlux) {
    const optics::Lens lens = optics::loadLens(test::lensPath("anamorphic-2x-double-gauss-50mm.lens"));
    const ShapedTable table = buildShapedTable(lens, TableSettings{});
    const trace::ImageFrame frame{320, 181, 36.0 / 320};
    ShapedRenderSettings settings;
    settings.cullShare = 0.0;
    for (const auto& [x, y] : {std::pair{0.0, 0.0}, std::pair{0.0, 7.7}, std::pair{6.0, 4.0}, std::pair{12.5, 8.1}}) {
        const trace::Field field = trace::fieldForSensorPoint(lens, lens.sensorZ(), x, y);
        const ShapedRender shaped = renderShaped(table, {{field, {1.0, 1.0, 1.0}}}, frame, settings);
        trace::TracedFlareOptions o;
        o.frame = frame;
        o.field = field;
        o.cullFraction = 0.0;
        const trace::TracedFlare traced = trace::renderTracedFlare(lens, o);
        for (int c = 0; c < 3; ++c) {
            std::vector<double> ref(shaped.channel[c].size());
            for (std::size_t p = 0; p < ref.size(); ++p) ref[p] = traced.rgb[p * 3 + c];
            if (y == 0.0) {
                EXPECT_LT(relativeL2(shaped.channel[c], ref), 0.10) << "centre, channel " << c;
            }
            EXPECT_NEAR(sum(shaped.channel[c]) / sum(ref), 1.0, x > 12.0 ? 0.08 : 0.04)
                << x << ", " << y << " channel " << c;
        }
    }
}
