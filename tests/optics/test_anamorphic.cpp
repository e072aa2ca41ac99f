// Anamorphic surfaces against geometry written here: a cylinder's sag, normal and a ray's hit in
// closed form; a biconic whose two sections agree is the rotationally symmetric conic; and the bundled
// 2x anamorphic's first-order data against its thin-lens design (lenses/anamorphic-2x-...lens).

#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/paraxial.h"
#include "optics/real_ray.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>

#include "test_support.h"

using namespace ff;
using namespace ff::optics;

namespace {

Surface cylinderAlongY(double radius) {
    Surface s;
    s.radius = radius;
    s.shape = SurfaceShape::CylinderY; // its axis along y: curved in x
    return s;
}

} // namespace

// A circular cylinder of radius R whose axis runs along y through (0, *, R): z = R - sqrt(R^2 - x^2)
// whatever y, dz/dx = x / sqrt(R^2 - x^2), dz/dy = 0; and the sections the first-order data take.
TEST(Anamorphic, ACylindersSagAndSlopeAreTheCirclesInX) {
    for (const double R : {25.0, -40.0}) {
        const Surface s = cylinderAlongY(R);
        EXPECT_EQ(s.curvatureY(), 0.0);
        EXPECT_DOUBLE_EQ(s.curvatureX(), 1.0 / R);
        for (const double x : {0.0, 3.0, -11.5, 17.0})
            for (const double y : {0.0, 8.0, -20.0}) {
                const double expected = R - std::copysign(std::sqrt(R * R - x * x), R);
                ASSERT_TRUE(s.sagAt(x, y));
                EXPECT_NEAR(*s.sagAt(x, y), expected, 1e-12) << R << " " << x << " " << y;
                const auto g = s.sagGradient(x, y);
                ASSERT_TRUE(g);
                EXPECT_NEAR(g->x, x / std::copysign(std::sqrt(R * R - x * x), R), 1e-12);
                EXPECT_EQ(g->y, 0.0);
            }
    }
    Surface turned = cylinderAlongY(30.0);
    turned.shape = SurfaceShape::CylinderX; // its axis along x: curved in y
    EXPECT_NEAR(*turned.sagAt(7.0, 0.0), 0.0, 0.0);
    EXPECT_NEAR(*turned.sagAt(0.0, 7.0), 30.0 - std::sqrt(900.0 - 49.0), 1e-12);
}

// The sag's range over a disc of radius r (what the Embree scene bounds a surface by) and around its
// rim (where the barrel starts and ends): a cylinder's runs from 0 (on its axis; at y = +-r on the
// rim) to the circle's R - sqrt(R^2 - r^2) at x = +-r (negative for R < 0); a rotationally symmetric
// surface's from 0 to its sag at r, and its rim's is that sag alone.
TEST(Anamorphic, ASurfacesSagRangeOverADiscAndItsRimAreItsCirclesInX) {
    const double r = 10.0;
    for (const double R : {25.0, -40.0}) {
        const auto range = cylinderAlongY(R).sagRange(r);
        ASSERT_TRUE(range);
        const double rim = R - std::copysign(std::sqrt(R * R - r * r), R);
        EXPECT_NEAR(range->first, std::min(0.0, rim), 1e-12) << R;
        EXPECT_NEAR(range->second, std::max(0.0, rim), 1e-12) << R;
        // Around the rim of radius r: the circle's value at x = +-r, 0 at y = +-r.
        const auto around = cylinderAlongY(R).rimRange(r);
        ASSERT_TRUE(around);
        EXPECT_NEAR(around->first, std::min(0.0, rim), 1e-12) << R;
        EXPECT_NEAR(around->second, std::max(0.0, rim), 1e-12) << R;
    }
    Surface sphere;
    sphere.radius = 25.0;
    const auto range = sphere.sagRange(r);
    ASSERT_TRUE(range);
    EXPECT_EQ(range->first, 0.0);
    EXPECT_NEAR(range->second, 25.0 - std::sqrt(625.0 - 100.0), 1e-12);
    EXPECT_EQ(sphere.rimRange(r), std::pair(*sphere.sag(r), *sphere.sag(r)));
}

// A skew ray against the cylinder (x^2 + (z - R)^2 = R^2, y free), solved here as a quadratic in t;
// the normal there is the circle's, (-x, 0, R - z) / R.
TEST(Anamorphic, ARayMeetsACylinderWhereTheQuadraticSays) {
    const double R = 25.84, vertexZ = 3.0;
    const Surface s = cylinderAlongY(R);
    for (const glm::dvec3 dir : {glm::dvec3(0.1, -0.2, 1.0), glm::dvec3(-0.3, 0.05, 1.0), glm::dvec3(0.0, 0.4, 1.0)}) {
        const Ray ray{{4.0, -2.0, -5.0}, glm::normalize(dir)};
        // (ox + t dx)^2 + (oz - vertexZ + t dz - R)^2 = R^2, the root on the vertex's side.
        const glm::dvec3 o = ray.origin, d = ray.dir;
        const double ez = o.z - vertexZ - R;
        const double a = d.x * d.x + d.z * d.z, b = 2.0 * (o.x * d.x + ez * d.z), c = o.x * o.x + ez * ez - R * R;
        const double t = (-b - std::sqrt(b * b - 4.0 * a * c)) / (2.0 * a);
        const glm::dvec3 expected = o + t * d;
        const auto hit = intersectSurface(s, vertexZ, ray, 0.0);
        ASSERT_TRUE(hit);
        EXPECT_NEAR(hit->t, t, 1e-10);
        EXPECT_NEAR(glm::length(hit->point - expected), 0.0, 1e-10);
        const glm::dvec3 n = glm::dvec3(-expected.x, 0.0, R - (expected.z - vertexZ)) / R;
        EXPECT_NEAR(glm::length(hit->normal - n), 0.0, 1e-10);
    }
}

// A biconic whose sections are the same conic is that rotationally symmetric surface: the same hit
// and normal for rays anywhere on it.
TEST(Anamorphic, ABiconicWithEqualSectionsIsTheRotationalConic) {
    Surface round;
    round.radius = -32.0;
    round.conic = -0.6;
    Surface biconic = round;
    biconic.shape = SurfaceShape::Biconic;
    biconic.radiusX = -32.0;
    biconic.conicX = -0.6;
    for (const glm::dvec3 origin :
         {glm::dvec3(0.0, 0.0, -1.0), glm::dvec3(7.0, -3.0, -4.0), glm::dvec3(-9.0, 12.0, 2.0)}) {
        const Ray ray{origin, glm::normalize(glm::dvec3(0.05, -0.1, 1.0))};
        const auto a = intersectSurface(round, 10.0, ray, 0.0), b = intersectSurface(biconic, 10.0, ray, 0.0);
        ASSERT_TRUE(a);
        ASSERT_TRUE(b);
        EXPECT_NEAR(glm::length(a->point - b->point), 0.0, 1e-10);
        EXPECT_NEAR(glm::length(a->normal - b->normal), 0.0, 1e-12);
    }
}

// The bundled 2x anamorphic: its attachment's numbers derived here from the file's radii and the
// catalogue index (f = R / (n - 1) for a lens with one flat face), against the first-order data.
TEST(Anamorphic, TheBundled2xAnamorphicHasItsDesignedFocalLengths) {
    const Lens lens = loadLens(test::lensPath("anamorphic-2x-double-gauss-50mm.lens"));
    const Lens prime = loadLens(test::lensPath("double-gauss-50mm-f2.lens"));
    ASSERT_FALSE(lens.rotationallySymmetric());
    const double n = lens.surfaces[0].medium.index(lines::d);
    const double f1 = -lens.surfaces[1].radius / (n - 1.0), f2 = lens.surfaces[2].radius / (n - 1.0);
    EXPECT_NEAR(f1, -50.0, 1e-3);
    EXPECT_NEAR(f2, 100.0, 1e-3);
    // Afocal: principal planes f1 + f2 apart (to the catalogue index's 8th digit, which the design rounds).
    EXPECT_NEAR(lens.surfaces[1].thickness, f1 + f2, 1e-4);
    const double magnification = -f1 / f2, primeEfl = paraxialEfl(prime, lines::d);
    const FirstOrder y = analyzeFirstOrder(sectionOf(lens, Section::Y), lines::d);
    const FirstOrder x = analyzeFirstOrder(sectionOf(lens, Section::X), lines::d);
    // Thin-lens design: EFL y = the prime's (plates), EFL x = |f1| / f2 x the prime's; within 0.5 %.
    EXPECT_NEAR(y.efl / primeEfl, 1.0, 5e-3);
    EXPECT_NEAR(x.efl / (magnification * primeEfl), 1.0, 5e-3);
    EXPECT_NEAR(y.efl / x.efl, 2.0, 0.02); // the squeeze, 2.0 +- 1 %
    // The afocal attachment leaves both sections' focus where the prime's is.
    EXPECT_NEAR(x.bfd, y.bfd, 1e-6);
    EXPECT_NEAR(y.bfd, paraxialBfd(prime, lines::d), 1e-6);
    // Real rays through the cylinders (exact surfaces) in each section give the same focal lengths.
    EXPECT_NEAR(realRayEfl(lens, lines::d, 1e-3, Section::Y) / y.efl, 1.0, 1e-6);
    EXPECT_NEAR(realRayEfl(lens, lines::d, 1e-3, Section::X) / x.efl, 1.0, 1e-6);
    // A rotationally symmetric lens is its own section.
    EXPECT_EQ(analyzeFirstOrder(sectionOf(prime, Section::X), lines::d).efl, paraxialEfl(prime, lines::d));
}

// The tracer's stages refuse an anamorphic lens with the reason, and a torus (no exact shape here)
// cannot be traced even for a real ray.
TEST(Anamorphic, TracersRefuseWhatTheyCannotTrace) {
    const Lens lens = loadLens(test::lensPath("anamorphic-2x-double-gauss-50mm.lens"));
    EXPECT_THROW(requireTraceable(lens), Error);
    const Lens toric = parseLensText(
        "name: t\nsurfaces:\n  30 4 1.5 60 10 1 toric 40\n  0 2 air 8 0 stop\n  -40 30 1 0 9 1\n", "t.lens");
    EXPECT_THROW(realRayEfl(toric, lines::d, 1e-3), Error);
}
