#include "ghosts/ghost_table.h"
#include "ghosts/instancing.h"
#include "optics/lens_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "test_support.h"

using namespace ff;
using namespace ff::ghosts;

namespace {

const GhostTable& table() {
    static const GhostTable t = [] {
        TableSettings s;
        s.grid = 12;
        s.angles = 11;
        s.maxAngleDeg = 15.0;
        return buildGhostTable(optics::loadLens(test::lensPath("cooke-triplet-50mm-f5.lens")), s);
    }();
    return t;
}

} // namespace

TEST(Instancing, FieldAngleInvertsTheDirectImageHeight) {
    const GhostTable& t = table();
    for (double a : {2.0, 7.3, 12.0}) EXPECT_NEAR(fieldAngleForRadius(t, t.directAt(1, a)), a, 1e-9);
}

TEST(Instancing, ALightAtAnyAzimuthIsTheRotatedTableEntry) {
    // The same distance from the centre straight above (azimuth 0 in sensor terms: image up) and to
    // the right: every ghost keeps its flux and widths and its centre turns with the light.
    const GhostTable& t = table();
    const trace::ImageFrame cam{1000, 800, 36.0 / 1000};
    const double rPx = 150.0;
    const std::vector<Light> lights = {{500.0, 400.0 - rPx, {2.0, 1.0, 0.5}}, {500.0 + rPx, 400.0, {2.0, 1.0, 0.5}}};
    const auto inst = instantiate(t, lights, cam);
    const double angle = fieldAngleForRadius(t, rPx * cam.pitchMm);
    std::size_t checked = 0;
    for (const GhostInstance& up : inst) {
        if (up.light != 0) continue;
        const GhostInstance* right = nullptr;
        for (const GhostInstance& g : inst)
            if (g.light == 1 && g.ghost == up.ghost) right = &g;
        ASSERT_NE(right, nullptr);
        const double m = t.magnification(up.ghost, 1, angle);
        // Straight up: centre at (cx, cy - m r); to the right: (cx + m r, cy).
        EXPECT_NEAR(up.xPx, 500.0, 1e-9);
        EXPECT_NEAR(up.yPx, 400.0 - m * rPx, 1e-6);
        EXPECT_NEAR(right->xPx, 500.0 + m * rPx, 1e-6);
        EXPECT_NEAR(right->yPx, 400.0, 1e-6);
        EXPECT_NEAR(up.radialAngle, -0.5 * std::numbers::pi, 1e-12);
        EXPECT_NEAR(right->radialAngle, 0.0, 1e-12);
        for (int c = 0; c < 3; ++c) {
            EXPECT_DOUBLE_EQ(up.flux[c], right->flux[c]);
            EXPECT_DOUBLE_EQ(up.widthR[c], right->widthR[c]);
        }
        // Flux = the light's flux x the ghost's relative flux at that angle (green: 550 nm).
        EXPECT_NEAR(up.flux[1], 1.0 * t.at(up.ghost, 1, angle).flux, 1e-15);
        EXPECT_NEAR(up.widthR[1], t.at(up.ghost, 1, angle).gaussian.widthR / cam.pitchMm, 1e-9);
        ++checked;
    }
    EXPECT_GT(checked, 5u);
}
