// Rays through graded-index media (optics/gradient_index.h) against closed forms derived here:
// the sech rod's meridional rays and optical path, the integrator's order, a gradient of zeros
// against the straight ray, and a Wood lens's focal length against its paraxial formula.

#include "optics/gradient_index.h"
#include "optics/real_ray.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>

namespace ff::optics {
namespace {

constexpr double kAlpha = 0.5, kN0 = 1.6; // the rod: n = n0 sech(alpha r), pitch 2 pi / alpha

// sech x = sum_k E_2k x^2k / (2k)! (Euler numbers): the rod's coefficients of r^2 .. r^16. Over
// alpha r <= 0.1 the first term left out (x^18) is below 1e-21 of n0.
GradientIndex sechRod() {
    const std::array<double, 8> euler = {-1.0, 5.0, -61.0, 1385.0, -50521.0, 2702765.0, -199360981.0, 19391512145.0};
    GradientIndex g;
    double factorial = 1.0, power = 1.0;
    for (int k = 1; k <= 8; ++k) {
        factorial *= (2.0 * k - 1.0) * (2.0 * k);
        power *= kAlpha * kAlpha;
        g.radial.push_back({kN0 * euler[static_cast<std::size_t>(k - 1)] * power / factorial, 0.0});
    }
    return g;
}

Surface flat() {
    return Surface{};
}

// A meridional ray in the sech rod: with u = sinh(alpha r) and beta = n cos(theta) conserved,
// beta^2 r'^2 = n^2 - beta^2 gives u'^2 + alpha^2 u^2 = const, so u(z) = u0 cos(alpha z) +
// (u0' / alpha) sin(alpha z), u0' = alpha cosh(alpha r0) tan(theta0): an exact sinusoid in u with
// pitch 2 pi / alpha for every ray.
double sechRodHeight(double r0, double theta0, double z) {
    const double u0 = std::sinh(kAlpha * r0), du0 = kAlpha * std::cosh(kAlpha * r0) * std::tan(theta0);
    return std::asinh(u0 * std::cos(kAlpha * z) + du0 / kAlpha * std::sin(kAlpha * z)) / kAlpha;
}

// Its slope dr/dz = u' / (alpha cosh(alpha r)).
double sechRodSlope(double r0, double theta0, double z) {
    const double u0 = std::sinh(kAlpha * r0), du0 = kAlpha * std::cosh(kAlpha * r0) * std::tan(theta0);
    const double du = -u0 * kAlpha * std::sin(kAlpha * z) + du0 * std::cos(kAlpha * z);
    return du / (kAlpha * std::cosh(kAlpha * sechRodHeight(r0, theta0, z)));
}

Ray rodRay(double r0, double theta0) {
    return {{r0, 0.0, 0.0}, {std::sin(theta0), 0.0, std::cos(theta0)}};
}

TEST(GradientIndex, SechRodRaysAreTheClosedFormSinusoids) {
    const GradientField field(kN0, sechRod(), 587.56, 0.0);
    const double pitch = 2.0 * std::numbers::pi / kAlpha;
    for (const auto& [r0, theta0] :
         {std::array<double, 2>{0.05, 0.08}, std::array<double, 2>{-0.1, 0.03}, std::array<double, 2>{0.0, -0.09}})
        for (int j = 1; j <= 12; ++j) {
            const double z = 3.0 * pitch * j / 12.0;
            const auto hit =
                propagate(field, rodRay(r0, theta0).origin, rodRay(r0, theta0).dir, flat(), 0.0, flat(), z);
            ASSERT_TRUE(hit);
            EXPECT_NEAR(hit->point.z, z, 1e-12);
            EXPECT_NEAR(hit->point.x, sechRodHeight(r0, theta0, z), 1e-6) << r0 << " " << theta0 << " " << z;
            EXPECT_EQ(hit->point.y, 0.0);
        }
}

// Over whole pitches every meridional ray of the sech rod has the same optical path: with
// n^2 = n0^2 / (1 + u^2), dL/dz = n^2 / beta and u = U sin(alpha z + phi), 1 + U^2 = n0^2 / beta^2,
// a pitch gives (n0^2 / beta) (2 pi / alpha) / sqrt(1 + U^2) = 2 pi n0 / alpha.
TEST(GradientIndex, SechRodOpticalPathIsTheClosedForm) {
    const GradientField field(kN0, sechRod(), 587.56, 0.0);
    const double pitch = 2.0 * std::numbers::pi / kAlpha;
    for (const auto& [r0, theta0] : {std::array<double, 2>{0.05, 0.08}, std::array<double, 2>{0.18, 0.0}}) {
        const auto hit =
            propagate(field, rodRay(r0, theta0).origin, rodRay(r0, theta0).dir, flat(), 0.0, flat(), 2.0 * pitch);
        ASSERT_TRUE(hit);
        EXPECT_NEAR(hit->opticalPath, 2.0 * 2.0 * std::numbers::pi * kN0 / kAlpha, 1e-8);
    }
}

// Fixed steps: halving the step divides the error of RK4 by 2^4. The error is taken in the phase
// plane (height, slope / alpha): the height's error alone passes through zero as the ray turns.
TEST(GradientIndex, HalvingTheStepDividesTheErrorBySixteen) {
    const GradientField field(kN0, sechRod(), 587.56, 0.0);
    const double z = 1.3 * 2.0 * std::numbers::pi / kAlpha;
    const auto error = [&](double h) {
        GradientSettings s;
        s.step = h;
        const auto hit =
            propagate(field, rodRay(0.05, 0.08).origin, rodRay(0.05, 0.08).dir, flat(), 0.0, flat(), z, 0.0, s);
        EXPECT_TRUE(hit);
        if (!hit) return 0.0;
        return std::hypot(hit->point.x - sechRodHeight(0.05, 0.08, z),
                          (hit->dir.x / hit->dir.z - sechRodSlope(0.05, 0.08, z)) / kAlpha);
    };
    for (const double h : {0.8, 0.4, 0.2}) {
        const double coarse = error(h), fine = error(h / 2);
        EXPECT_GT(fine, 1e-12); // far above rounding
        EXPECT_NEAR(coarse / fine, 16.0, 0.3 * 16.0) << "h = " << h;
    }
}

// All coefficients zero: the homogeneous medium's straight ray, between curved surfaces.
TEST(GradientIndex, ZeroGradientIsTheHomogeneousRay) {
    GradientIndex zeros;
    zeros.radial = {{0.0, 0.0}, {0.0, 0.0}};
    zeros.axial = {{0.0, 0.0}};
    const double n0 = 1.62;
    const GradientField field(n0, zeros, 486.13, 0.0);
    Surface front, back;
    front.radius = 40.0;
    back.radius = -25.0;
    back.asphere = {1e-6};
    const double backZ = 6.0;
    for (const auto& [x, y, dx, dy] :
         {std::array<double, 4>{0.0, 0.0, 0.0, 0.0}, std::array<double, 4>{3.0, -2.0, 0.1, 0.05},
          std::array<double, 4>{-5.0, 4.0, -0.2, 0.15}}) {
        const double z = *front.sag(std::hypot(x, y));
        const Ray ray{{x, y, z}, glm::normalize(glm::dvec3(dx, dy, 1.0))};
        const auto straight = intersectSurface(back, backZ, ray, 1e-9);
        const auto curved = propagate(field, ray.origin, ray.dir, front, 0.0, back, backZ);
        ASSERT_TRUE(straight && curved);
        EXPECT_LT(glm::length(curved->point - straight->point), 1e-9);
        EXPECT_LT(glm::length(curved->dir - ray.dir), 1e-12);
        EXPECT_LT(glm::length(curved->normal - straight->normal), 1e-9);
        EXPECT_NEAR(curved->opticalPath, n0 * straight->t, 1e-9);
        EXPECT_EQ(curved->index, n0);
    }
}

// A Wood lens (a flat slab, n = n0 + a1 r^2, a1 < 0) in air. Paraxially r'' = -A r inside, A =
// -2 a1 / n0, so a ray entering parallel at height h leaves at h cos(sqrt(A) d) with the slope
// -n0 h sqrt(A) sin(sqrt(A) d): f = 1 / (n0 sqrt(A) sin(sqrt(A) d)) (-> 1 / (-2 a1 d) when thin).
TEST(GradientIndex, WoodLensFocalLengthIsTheParaxialFormula) {
    const double n0 = 1.5, a1 = -0.002;
    for (const double d : {1.0, 4.0, 10.0}) {
        GradientIndex g;
        g.radial = {{a1, 0.0}};
        const GradientField field(n0, g, 587.56, 0.0);
        const double h = 1e-3;
        GradientSettings precise;
        precise.tolerance = 1e-13;
        const auto hit = propagate(field, {h, 0.0, 0.0}, {0.0, 0.0, 1.0}, flat(), 0.0, flat(), d, 0.0, precise);
        ASSERT_TRUE(hit);
        const auto out = refract(hit->dir, hit->normal, hit->index, 1.0);
        ASSERT_TRUE(out);
        const double efl = -h / (out->x / out->z);
        const double A = -2.0 * a1 / n0;
        const double expected = 1.0 / (n0 * std::sqrt(A) * std::sin(std::sqrt(A) * d));
        EXPECT_NEAR(efl / expected, 1.0, 1e-6) << "d = " << d;
        if (d == 1.0) {
            EXPECT_NEAR(efl * (-2.0 * a1 * d), 1.0, 2e-3); // the thin lens
        }
    }
}

// Each coefficient's dispersion: c(lambda) = c_d + D (1 / L^2 - 1 / L_d^2).
TEST(GradientIndex, CoefficientsDisperseInCauchyForm) {
    const GradientTerm t{-0.002, 1e-4};
    EXPECT_DOUBLE_EQ(t.at(587.5618), -0.002);
    EXPECT_NEAR(t.at(486.1327), -0.002 + 1e-4 * (1.0 / (0.4861327 * 0.4861327) - 1.0 / (0.5875618 * 0.5875618)), 1e-15);
}

// Lost rays: one that turns back across the surface it left, one that leaves the clear radius.
TEST(GradientIndex, RaysThatCannotArriveAreLost) {
    GradientIndex g;
    g.axial = {{-0.5, 0.0}}; // n falls steeply along z: an oblique ray turns back
    const GradientField field(1.9, g, 587.56, 0.0);
    EXPECT_FALSE(
        propagate(field, {0.0, 0.0, 0.0}, glm::normalize(glm::dvec3(1.0, 0.0, 0.3)), flat(), 0.0, flat(), 5.0));
    const GradientField rod(kN0, sechRod(), 587.56, 0.0);
    EXPECT_FALSE(propagate(rod, rodRay(0.05, 0.08).origin, rodRay(0.05, 0.08).dir, flat(), 0.0, flat(), 20.0, 0.1));
    EXPECT_TRUE(propagate(rod, rodRay(0.05, 0.08).origin, rodRay(0.05, 0.08).dir, flat(), 0.0, flat(), 20.0, 0.3));
}

} // namespace
} // namespace ff::optics
