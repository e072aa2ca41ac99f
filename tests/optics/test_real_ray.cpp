#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/real_ray.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test_support.h"

using namespace ff;
using namespace ff::optics;

TEST(RealRay, ParallelRayHitsSphereWhereGeometrySays) {
    // Sphere of radius R with its vertex at z = 5: a ray at height h parallel to the axis meets it
    // at z = 5 + R - sqrt(R^2 - h^2), with the normal pointing from the centre (0, 0, 5 + R).
    Surface s;
    s.radius = 40.0;
    const double h = 12.0;
    auto hit = intersectSurface(s, 5.0, {{0.0, h, -100.0}, {0.0, 0.0, 1.0}});
    ASSERT_TRUE(hit);
    const double z = 5.0 + 40.0 - std::sqrt(40.0 * 40.0 - h * h);
    EXPECT_NEAR(hit->point.z, z, 1e-12);
    EXPECT_NEAR(hit->point.y, h, 1e-12);
    const glm::dvec3 expectedNormal = glm::normalize(glm::dvec3(0.0, 0.0, 45.0) - hit->point);
    EXPECT_NEAR(glm::dot(hit->normal, expectedNormal), 1.0, 1e-14);
}

TEST(RealRay, VertexBranchIsFoundFromFarAwayAndFromBehind) {
    // A concave surface (R = -14.5) seen from 26 mm in front, and a ray travelling backwards (-z):
    // both must hit near the vertex, not on the far side of the sphere.
    Surface s;
    s.radius = -14.5;
    auto fwd = intersectSurface(s, 0.0, {{0.0, 0.5, -26.0}, {0.0, 0.0, 1.0}});
    ASSERT_TRUE(fwd);
    EXPECT_NEAR(fwd->point.z, *s.sag(0.5), 1e-12);
    auto back = intersectSurface(s, 0.0, {{0.0, 0.5, 30.0}, {0.0, 0.0, -1.0}});
    ASSERT_TRUE(back);
    EXPECT_NEAR(back->point.z, *s.sag(0.5), 1e-12);
}

TEST(RealRay, EvenAsphereHitLiesOnTheSag) {
    Surface s;
    s.radius = 30.0;
    s.conic = -0.7;
    s.asphere = {1e-5, -2e-8, 3e-11};
    const glm::dvec3 dir = glm::normalize(glm::dvec3(0.05, -0.1, 1.0));
    auto hit = intersectSurface(s, 2.0, {{1.0, 8.0, -10.0}, dir});
    ASSERT_TRUE(hit);
    const double r = std::hypot(hit->point.x, hit->point.y);
    EXPECT_NEAR(hit->point.z - 2.0, *s.sag(r), 1e-12);
    // The normal is perpendicular to the surface: along (-z'(r) x/r, -z'(r) y/r, 1).
    const double slope = *s.sagSlope(r);
    const glm::dvec3 n = glm::normalize(glm::dvec3(-slope * hit->point.x / r, -slope * hit->point.y / r, 1.0));
    EXPECT_NEAR(glm::dot(n, hit->normal), 1.0, 1e-14);
}

TEST(RealRay, RefractionObeysSnellsLaw) {
    const glm::dvec3 n(0.0, 0.0, 1.0);
    const double theta = 0.6;
    const glm::dvec3 d(std::sin(theta), 0.0, std::cos(theta));
    auto t = refract(d, n, 1.0, 1.5);
    ASSERT_TRUE(t);
    EXPECT_NEAR(1.0 * std::sin(theta), 1.5 * t->x, 1e-15);
    EXPECT_NEAR(glm::length(*t), 1.0, 1e-15);
    EXPECT_GT(t->z, 0.0);
    // From glass to air beyond the critical angle asin(1/1.5) = 0.7297: total internal reflection.
    const glm::dvec3 steep(std::sin(0.8), 0.0, std::cos(0.8));
    EXPECT_FALSE(refract(steep, n, 1.5, 1.0));
    EXPECT_TRUE(refract(glm::dvec3(std::sin(0.7), 0.0, std::cos(0.7)), n, 1.5, 1.0));
}

TEST(RealRay, ReflectionMirrorsTheNormalComponent) {
    const glm::dvec3 r = reflect(glm::normalize(glm::dvec3(1.0, 0.0, 1.0)), glm::dvec3(0.0, 0.0, -1.0));
    EXPECT_NEAR(r.x, std::sqrt(0.5), 1e-15);
    EXPECT_NEAR(r.z, -std::sqrt(0.5), 1e-15);
}

TEST(RealRay, ClippingAndStatusOfALostRay) {
    const Lens lens = loadLens(test::lensPath("double-gauss-50mm-f2.lens"));
    // A ray at 13 mm misses the 12.6 mm clear aperture of surface 1.
    const RealTraceResult r = traceReal(lens, lines::d, {{0.0, 13.0, -5.0}, {0.0, 0.0, 1.0}});
    EXPECT_EQ(r.status, RayStatus::Clipped);
    EXPECT_EQ(r.surface, 0u);
    const RealTraceResult ok = traceReal(lens, lines::d, {{0.0, 5.0, -5.0}, {0.0, 0.0, 1.0}});
    EXPECT_EQ(ok.status, RayStatus::Ok);
}

TEST(RealRay, SnellAndReflectionLawsHoldOnRandomSkewRays) {
    // Vector Snell: n1 (d x n) = n2 (t x n) (tangential momentum, which also makes d, n, t coplanar),
    // t stays on the far side. Reflection: the tangential part is kept, the normal part flips.
    std::mt19937 rng(3);
    std::normal_distribution<double> g(0.0, 1.0);
    std::uniform_real_distribution<double> idx(1.0, 2.0);
    auto unit = [&] { return glm::normalize(glm::dvec3(g(rng), g(rng), g(rng))); };
    int refracted = 0;
    for (int k = 0; k < 2000; ++k) {
        const glm::dvec3 d = unit(), n = unit();
        const double n1 = idx(rng), n2 = idx(rng);
        const glm::dvec3 r = reflect(d, n);
        EXPECT_NEAR(glm::length(r), 1.0, 1e-12);
        EXPECT_NEAR(glm::dot(r, n), -glm::dot(d, n), 1e-12);
        EXPECT_LT(glm::length((r - glm::dot(r, n) * n) - (d - glm::dot(d, n) * n)), 1e-12);
        const auto t = refract(d, n, n1, n2);
        const double sinI = glm::length(glm::cross(d, n));
        if (!t) {
            EXPECT_GT(n1 * sinI, n2 * (1.0 - 1e-12)); // only beyond the critical angle
            continue;
        }
        ++refracted;
        EXPECT_NEAR(glm::length(*t), 1.0, 1e-12);
        EXPECT_LT(glm::length(n1 * glm::cross(d, n) - n2 * glm::cross(*t, n)), 1e-12);
        EXPECT_GT(glm::dot(*t, n) * glm::dot(d, n), 0.0);
    }
    EXPECT_GT(refracted, 1000);
}
