// Tracing through the bundled 2x anamorphic (lenses/anamorphic-2x-double-gauss-50mm.lens): the field
// that images a source at a sensor point (a two-dimensional solve without rotational symmetry)
// against the thin-lens design's focal length in each section, and the light it finds landing there.

#include "core/units.h"
#include "optics/lens_loader.h"
#include "trace/bundle.h"
#include "trace/sensor.h"
#include "trace/sequential_tracer.h"
#include "trace/traced_flare.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "test_support.h"
#include "uniform_ellipse.h"

using namespace ff;
using namespace ff::trace;

namespace {

const optics::Lens& anamorphic() {
    static const optics::Lens lens = optics::loadLens(test::lensPath("anamorphic-2x-double-gauss-50mm.lens"));
    return lens;
}

// The transverse direction (sin of the field angle along the image's direction) of a field.
glm::dvec2 transverse(const Field& f) {
    return std::sin(f.angleRad) * glm::dvec2(-std::sin(f.azimuthRad), std::cos(f.azimuthRad));
}

} // namespace

// Near the axis a source imaged at (x, y) comes from tan(theta_x) = x / f_x, tan(theta_y) = y / f_y
// with the design's focal lengths: f_y = 50.358 mm (the prime) and f_x = f_y / 2 (the attachment's
// angular magnification, 1/2 in x). theta_x and theta_y are the direction's slopes in each section.
TEST(AnamorphicTrace, TheFieldOfASensorPointFollowsEachSectionsFocalLength) {
    const optics::Lens& lens = anamorphic();
    const double fy = 50.358, fx = 0.5 * fy;
    for (const auto& [x, y] : {std::pair{0.2, 0.0}, std::pair{0.0, 0.2}, std::pair{0.15, -0.1}}) {
        const Field f = fieldForSensorPoint(lens, lens.sensorZ(), x, y);
        const glm::dvec2 u = transverse(f);
        const double uz = std::cos(f.angleRad);
        EXPECT_NEAR(u.x / uz, x / fx, 2e-3 * std::abs(x / fx) + 1e-9) << x << ", " << y;
        EXPECT_NEAR(u.y / uz, y / fy, 2e-3 * std::abs(y / fy) + 1e-9) << x << ", " << y;
    }
}

// Wherever the solve lands, the chief ray of the field it returns, aimed through the stop's centre,
// lands on the asked point (to 1e-6 mm), on the axes, off them and near a corner of the sensor.
TEST(AnamorphicTrace, TheChiefRayOfTheFieldLandsOnTheAskedPoint) {
    const optics::Lens& lens = anamorphic();
    const double sensorZ = lens.sensorZ();
    const LensAtWavelength L(lens, 587.5618, sensorZ);
    const PupilFrame pupil = pupilFrame(lens);
    const auto steps = pathSteps(lens, std::nullopt);
    std::size_t stopStep = 0;
    for (std::size_t k = 0; k < steps.size(); ++k)
        if (steps[k].surface == L.stop) stopStep = k;
    for (const auto& [x, y] :
         {std::pair{4.5, 0.0}, std::pair{9.0, 0.0}, std::pair{0.0, 6.0}, std::pair{-7.5, 4.0}, std::pair{12.0, -8.0}}) {
        const Field f = fieldForSensorPoint(lens, sensorZ, x, y);
        // Aim through the stop's centre by a scan of the pupil plane for the stop point nearest it:
        // coarse over three times the pupil's radius (an anamorphic's pupils in x and y lie in
        // different planes), then fine around the best.
        std::vector<double> margins(steps.size());
        std::vector<glm::dvec3> points(steps.size());
        double best = 1e300;
        glm::dvec2 landed(0.0), centre(0.0);
        double half = 3.0 * pupil.radius;
        for (int pass = 0; pass < 3; ++pass) {
            const int n = 100;
            const glm::dvec2 around = centre;
            for (int j = 0; j <= n; ++j)
                for (int i = 0; i <= n; ++i) {
                    const glm::dvec2 p = around + half * glm::dvec2(2.0 * i / n - 1.0, 2.0 * j / n - 1.0);
                    const Bundle one = gridBundle(pupil, f, 1, p.x, p.y, 1e-9, false);
                    const SequentialResult r =
                        traceSequential(L, steps, one.rays[0], Weighting::Fresnel, margins.data(), points.data());
                    if (r.status != optics::RayStatus::Ok) continue;
                    const double d = glm::length(glm::dvec2(points[stopStep]));
                    if (d < best) best = d, landed = glm::dvec2(r.ray.origin), centre = p;
                }
            half *= 4.0 / n;
        }
        // The scans put the best ray within 1e-4 mm of the stop's centre; a chief ray's neighbours
        // that close land within 1e-4 mm of it.
        EXPECT_LT(best, 1e-3) << x << ", " << y;
        EXPECT_NEAR(landed.x, x, 1e-3) << x << ", " << y;
        EXPECT_NEAR(landed.y, y, 1e-3) << x << ", " << y;
    }
}

// One cylinder's ghost in closed form. An uncoated plate (n = 1.5, non-dispersive, 5 mm thick)
// behind a 5 mm stop, its back face a biconic of radius Rx = 400 mm in x and Ry = 1e6 mm in y (the
// tracer needs a lens with power in both sections), the sensor D = 50 mm behind it, lit on axis by a
// collimated beam. The one ghost reflects off the back face, then the front, then leaves through the
// back. Paraxially, in each section of curvature c = 1/R: a ray at height h reflects off the back
// face (a convex mirror seen from the glass, for R > 0) with slope 2 c h, reaches the back face again
// at h2 = h (1 + 4 t c) after 2 t of glass, refracts to n' u' = n u - (n' - n) c h2, i.e.
// u' = 1.5 (2 c h) + 0.5 c h2, and lands at h (1 + 4 t c) + D u'. So the stop's disc lands as an
// ellipse of semi-axes 5 m_x and 5 m_y, m = 1 + 4 t c + D c (3 + 0.5 (1 + 4 t c)): m_x = 1.4906,
// m_y = 1.0000. At normal incidence every ghost ray keeps R^2 (1 - R)^2 of its flux and every direct
// ray (1 - R)^2, R = ((n - 1) / (n + 1))^2 = 0.04 (the rays' slopes, at most 0.025, move the Fresnel
// factors by about 1e-4): the ghost holds R^2 of the direct flux, uniform over the ellipse (its
// aberrations, of order (h c)^2 ~ 2e-4, far below the tolerance).
TEST(AnamorphicTrace, ACylindricalPlatesGhostIsTheEllipseOfItsParaxialMagnifications) {
    test::TempDir dir;
    test::writeFile(dir / "cylinder.lens", "name: cylinder plate\nsensor: 36x24\nsurfaces:\n"
                                           "  stop 10 1.0 0 5 0\n"
                                           "  0 5 1.5 0 12 0\n"
                                           "  1e6 50 1.0 0 12 0 biconic=400\n");
    const optics::Lens lens = optics::loadLens(dir / "cylinder.lens");
    ASSERT_FALSE(lens.rotationallySymmetric());
    const double t = 5.0, D = 50.0, r = 5.0, R = 0.04;
    const auto magnification = [&](double c) { return 1.0 + 4.0 * t * c + D * c * (3.0 + 0.5 * (1.0 + 4.0 * t * c)); };
    const double ax = r * magnification(1.0 / 400.0), ay = r * magnification(1e-6);
    TracedFlareOptions o;
    const int W = 960, H = 640;
    const double pitch = 36.0 / W;
    o.frame = {W, H, pitch};
    const TracedFlare f = renderTracedFlare(lens, o);
    ASSERT_EQ(f.ghostCount, 1u);
    const std::vector<double> expected = test::uniformEllipse(o.frame, ax, ay, R * R);
    for (int c = 0; c < 3; ++c) {
        const test::Agreement a = test::agreement(f.rgb, c, expected);
        EXPECT_GE(a.lowest, 0.0) << "channel " << c;
        EXPECT_LE(a.relativeL2, 0.01) << "channel " << c;
        EXPECT_NEAR(a.sum, R * R, 2e-3 * R * R) << "channel " << c;
    }
}
