// Graded-index elements in the tracers (trace::nextHit, optics::traceReal, the paraxial trace):
// a gradient of zeros gives the homogeneous lens's rays and ghost energies; the Embree tracer agrees
// with the analytic one through a graded element; a Wood lens's focal length from the paraxial
// trace and from a real ray against its paraxial formula.

#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/paraxial.h"
#include "optics/real_ray.h"
#include "trace/embree_tracer.h"
#include "trace/pupil_sampling.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>

#include "test_support.h"

using namespace ff;
using namespace ff::trace;
using optics::RayStatus;

namespace {

std::vector<std::optional<GhostPair>> everyPath(const optics::Lens& lens) {
    std::vector<std::optional<GhostPair>> paths = {std::nullopt};
    for (const GhostPair& g : enumerateGhosts(lens)) paths.push_back(g);
    return paths;
}

} // namespace

TEST(GradientTrace, ZeroCoefficientsGiveTheHomogeneousLens) {
    const optics::Lens plain = optics::loadLens(test::sourceDir() / "lenses" / "cooke-triplet-50mm-f5.lens");
    optics::Lens graded = plain;
    for (std::size_t i : {0u, 2u}) // the front crown and the flint
        graded.surfaces[i].medium.gradient = optics::GradientIndex{{{0.0, 0.0}, {0.0, 0.0}}, {{0.0, 0.0}}, {}};
    EXPECT_NEAR(optics::paraxialEfl(graded, 550.0), optics::paraxialEfl(plain, 550.0), 1e-12 * 50.0);
    const LensAtWavelength A(plain, 550.0), B(graded, 550.0);
    const PupilFrame frame = pupilFrame(plain);
    std::size_t compared = 0;
    for (double deg : {0.0, 9.0}) {
        const Bundle b = gridBundle(frame, {degToRad(deg), 0.3}, 10, 0.0, 0.0, 1.1 * frame.radius, false);
        std::vector<RayResult> a(b.rays.size()), g(b.rays.size());
        for (const auto& path : everyPath(plain)) {
            const auto steps = pathSteps(plain, path);
            traceAnalytic(A, steps, b.rays, a);
            traceAnalytic(B, steps, b.rays, g);
            for (std::size_t i = 0; i < b.rays.size(); ++i) {
                ASSERT_EQ(a[i].status, g[i].status) << i;
                if (a[i].status != RayStatus::Ok) continue;
                EXPECT_LT(glm::length(a[i].sensorPoint - g[i].sensorPoint), 1e-9);
                EXPECT_NEAR(g[i].weight, a[i].weight, 1e-9 * a[i].weight);
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 1000u);
}

// A Wood lens (flat slab, n = n0 + a1 r^2) before the stop. Paraxially r'' = -A r inside, A = -2 a1 /
// n0, so f = 1 / (n0 sqrt(A) sin(sqrt(A) d)) and the back focal distance is cos(sqrt(A) d) f.
TEST(GradientTrace, WoodLensFocalLengthIsTheParaxialFormula) {
    const double n0 = 1.5, a1 = -0.002, d = 6.0;
    const optics::Lens lens = optics::parseLensText("name: wood\nsurfaces:\n"
                                                    "  0 6 1.5 0 5 0 grin_r=-0.002:0\n"
                                                    "  stop auto 1 0 5\n",
                                                    "wood.lens");
    const double A = -2.0 * a1 / n0, f = 1.0 / (n0 * std::sqrt(A) * std::sin(std::sqrt(A) * d));
    EXPECT_NEAR(optics::paraxialEfl(lens, lines::d) / f, 1.0, 1e-9);
    EXPECT_NEAR(lens.surfaces.back().thickness, std::cos(std::sqrt(A) * d) * f, 1e-6);
    // The real ray at 1e-3 mm: its aberrations, O((h / 5 mm)^2) = 4e-8, and the integrator's error, 1e-8
    // of the height per mm of path, stay under 1e-6.
    EXPECT_NEAR(optics::realRayEfl(lens, lines::d, 1e-3) / f, 1.0, 1e-6);
}

// The bundled GRIN rod: n = n0 (1 - A r^2 / 2), n0 = 1.608, sqrt(A) = 0.339 / mm, length 4.26 mm between
// flat faces (0.23 pitch). Paraxially r'' = -A r inside, so f = 1 / (n0 sqrt(A) sin(sqrt(A) L)) and the
// sensor ('auto') sits cos(sqrt(A) L) f behind the back face.
TEST(GradientTrace, BundledGrinRodIsTheSelfocFormula) {
    const optics::Lens lens = optics::loadLens(test::lensPath("grin-rod-1.8mm-0.23-pitch.lens"));
    const double n0 = 1.608, g = 0.339, L = 4.26;
    ASSERT_TRUE(lens.surfaces[0].medium.gradient);
    EXPECT_NEAR(lens.surfaces[0].medium.gradient->radial[0].atD, -n0 * g * g / 2.0, 1e-9);
    EXPECT_NEAR(g * L / (2.0 * std::acos(-1.0)), 0.23, 5e-4); // the pitch
    const double f = 1.0 / (n0 * g * std::sin(g * L));
    EXPECT_NEAR(optics::paraxialEfl(lens, lines::d) / f, 1.0, 1e-9);
    EXPECT_NEAR(lens.surfaces.back().thickness, std::cos(g * L) * f, 1e-6);
    EXPECT_NEAR(optics::realRayEfl(lens, lines::d, 1e-4) / f, 1.0, 1e-6);
}

// The Embree tracer follows the graded element's curved rays as the analytic tracer does, ghosts
// included (the rays reflected back through the slab).
TEST(GradientTrace, EmbreeAgreesWithTheAnalyticTracerThroughAGradedElement) {
    const optics::Lens lens =
        optics::parseLensText("name: wood pair\nsurfaces:\n"
                              "  40 6 1.6 40 8 1 grin_r=-0.002:1e-05 grin_z=0.004:0\n"
                              "  -60 2 air 8 1\n  stop 3 1 0 6\n  30 4 1.5 60 8 1\n  -80 auto 1 0 8\n",
                              "pair.lens");
    const LensAtWavelength L(lens, 550.0);
    const EmbreeTracer tracer(L);
    const PupilFrame frame = pupilFrame(lens);
    std::size_t compared = 0;
    for (double deg : {0.0, 6.0}) {
        const Bundle b = gridBundle(frame, {degToRad(deg), 0.3}, 10, 0.0, 0.0, 1.1 * frame.radius, false);
        std::vector<RayResult> e(b.rays.size()), a(b.rays.size());
        for (const auto& path : everyPath(lens)) {
            const auto steps = pathSteps(lens, path);
            tracer.trace(L, steps, b.rays, e);
            traceAnalytic(L, steps, b.rays, a);
            for (std::size_t i = 0; i < b.rays.size(); ++i) {
                if (e[i].status != RayStatus::Ok) continue;
                ASSERT_EQ(a[i].status, RayStatus::Ok) << i;
                EXPECT_LT(glm::length(e[i].sensorPoint - a[i].sensorPoint), 1e-9);
                EXPECT_EQ(e[i].weight, a[i].weight);
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 500u);
}
