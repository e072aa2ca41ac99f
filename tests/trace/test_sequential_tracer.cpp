#include "core/units.h"
#include "optics/glass_catalog.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/paraxial.h"
#include "optics/thin_film.h"
#include "trace/ghost_path.h"
#include "trace/sequential_tracer.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "test_support.h"

using namespace ff;
using namespace ff::trace;
using optics::Ray;
using optics::RayStatus;

namespace {

// A plane-parallel plate, thickness t, index n, between a stop and the sensor.
optics::Lens plate(double n, double t, int coating) {
    const std::string text = "surfaces:\n  stop 5 1 0 20\n  0 " + std::to_string(t) + " " + std::to_string(n) +
                             " 0 20 " + std::to_string(coating) + "\n  0 50 1 0 20 " + std::to_string(coating) + "\n";
    return optics::parseLensText(text, "plate.lens");
}

} // namespace

TEST(GhostPaths, CountIsPairsOfReflectingInterfaces) {
    for (const auto& entry : std::filesystem::directory_iterator(test::sourceDir() / "lenses")) {
        const optics::Lens lens = optics::loadLens(
            entry.path().extension() == ".lens" ? entry.path() : test::lensPath("cooke-triplet-50mm-f5.lens"));
        const std::size_t m = lens.reflectingInterfaces(lines::d).size();
        const auto ghosts = enumerateGhosts(lens);
        EXPECT_EQ(ghosts.size(), m * (m - 1) / 2) << entry.path();
        for (const GhostPair& g : ghosts) EXPECT_GT(g.first, g.second);
    }
}

TEST(GhostPaths, StepsGoForwardBackAndForward) {
    const optics::Lens lens = optics::loadLens(test::lensPath("cooke-triplet-50mm-f5.lens"));
    const GhostPair g{3, 1};
    EXPECT_EQ(g.label(), "R4\u2192R2");
    const std::vector<PathStep> expected = {{0, false}, {1, false}, {2, false}, {3, true},  {2, false},
                                            {1, true},  {2, false}, {3, false}, {4, false}, {5, false}};
    EXPECT_EQ(pathSteps(lens, g), expected);
    EXPECT_EQ(pathSteps(lens, std::nullopt).size(), 6u);
}

TEST(SequentialTracer, UncoatedPlateAtNormalIncidence) {
    // Direct: two transmissions, (1 - R)^2. Ghost (back face, then front face): (1 - R)^2 R^2,
    // with R = ((n - 1) / (n + 1))^2; the ghost lands where the direct ray does.
    const double n = 1.5, R = std::pow((n - 1.0) / (n + 1.0), 2);
    const optics::Lens lens = plate(n, 4.0, 0);
    const LensAtWavelength L(lens, 550.0);
    const Ray in{{0.0, 3.0, -1.0}, {0.0, 0.0, 1.0}};
    const auto direct = traceSequential(L, pathSteps(lens, std::nullopt), in);
    ASSERT_EQ(direct.status, RayStatus::Ok);
    EXPECT_NEAR(direct.weight, (1 - R) * (1 - R), 1e-15);
    const auto ghosts = enumerateGhosts(lens);
    ASSERT_EQ(ghosts.size(), 1u); // the flat air-air stop does not reflect
    const auto ghost = traceSequential(L, pathSteps(lens, ghosts[0]), in);
    ASSERT_EQ(ghost.status, RayStatus::Ok);
    EXPECT_NEAR(ghost.weight, (1 - R) * (1 - R) * R * R, 1e-15);
    EXPECT_NEAR(ghost.ray.origin.y, 3.0, 1e-12);
    EXPECT_NEAR(ghost.ray.origin.z, L.sensorZ, 1e-12);
}

TEST(SequentialTracer, TiltedPlateGhostIsDisplacedByTheDoublePass) {
    // Inside the plate the ray makes theta_t with the axis (sin theta = n sin theta_t); the ghost
    // crosses the plate twice more, so it leaves parallel to the direct ray, 2 t tan(theta_t) further
    // along y. R is the same on both faces (Fresnel is symmetric in the two media at matching angles).
    const double n = 1.6, t = 5.0, theta = 0.3;
    const double thetaT = std::asin(std::sin(theta) / n);
    const optics::Lens lens = plate(n, t, 0);
    const LensAtWavelength L(lens, 550.0);
    const Ray in{{0.0, -2.0, -1.0}, {0.0, std::sin(theta), std::cos(theta)}};
    const auto direct = traceSequential(L, pathSteps(lens, std::nullopt), in);
    const auto ghost = traceSequential(L, pathSteps(lens, enumerateGhosts(lens)[0]), in);
    ASSERT_EQ(direct.status, RayStatus::Ok);
    ASSERT_EQ(ghost.status, RayStatus::Ok);
    EXPECT_NEAR(ghost.ray.origin.y - direct.ray.origin.y, 2.0 * t * std::tan(thetaT), 1e-12);
    EXPECT_NEAR(ghost.ray.dir.y, direct.ray.dir.y, 1e-15);
    const double R = optics::fresnelReflectance(1.0, n, std::cos(theta));
    EXPECT_NEAR(ghost.weight, (1 - R) * (1 - R) * R * R, 1e-15);
}

TEST(SequentialTracer, CoatedPlateUsesTheQuarterWaveReflectance) {
    // Single MgF2 quarter wave at 550 nm on N-BK7, normal incidence:
    // R = ((n0 n2 - n1^2) / (n0 n2 + n1^2))^2 with the catalogue's indices at 550 nm.
    const auto& cat = optics::GlassCatalog::builtin();
    const double n1 = cat.find("MgF2")->dispersion.index(550.0), n2 = cat.find("N-BK7")->dispersion.index(550.0);
    const double R = std::pow((n2 - n1 * n1) / (n2 + n1 * n1), 2);
    const optics::Lens lens =
        optics::parseLensText("surfaces:\n  stop 5 1 0 20\n  0 4 N-BK7 20 1\n  0 50 air 20 1\n", "c.lens");
    const LensAtWavelength L(lens, 550.0);
    const auto ghost =
        traceSequential(L, pathSteps(lens, enumerateGhosts(lens)[0]), {{0.0, 1.0, -1.0}, {0.0, 0.0, 1.0}});
    ASSERT_EQ(ghost.status, RayStatus::Ok);
    EXPECT_NEAR(ghost.weight, (1 - R) * (1 - R) * R * R, 1e-14);
}

TEST(SequentialTracer, RaysOutsideTheApertureAreClipped) {
    const optics::Lens lens = optics::loadLens(test::lensPath("double-gauss-50mm-f2.lens"));
    const LensAtWavelength L(lens, lines::d);
    const auto steps = pathSteps(lens, std::nullopt);
    const auto outside = traceSequential(L, steps, {{0.0, 13.0, -1.0}, {0.0, 0.0, 1.0}});
    EXPECT_EQ(outside.status, RayStatus::Clipped);
    EXPECT_EQ(outside.lostAtStep, 0u);
    EXPECT_EQ(outside.weight, 0.0);
}

TEST(SequentialTracer, TheStopClipsAtItsWorkingOpening) {
    // Plano-convex lens, flat side first, n = 1.5, R2 = -50: f = -R2 / (n - 1) = 100 whatever its
    // thickness. The stop is the first surface, so it is the entrance pupil: f/8 gives r = 100 / 16.
    const optics::Lens lens =
        optics::parseLensText("f_number: 8\nsurfaces:\n  stop 1 1 0 0\n  0 3 1.5 0 30\n  -50 auto 1 0 30\n", "s.lens");
    const LensAtWavelength L(lens, lines::d);
    const auto steps = pathSteps(lens, std::nullopt);
    EXPECT_EQ(traceSequential(L, steps, {{0.0, 6.2, -1.0}, {0.0, 0.0, 1.0}}).status, RayStatus::Ok);
    const auto outside = traceSequential(L, steps, {{0.0, 6.3, -1.0}, {0.0, 0.0, 1.0}});
    EXPECT_EQ(outside.status, RayStatus::Clipped);
    EXPECT_EQ(steps[outside.lostAtStep].surface, lens.stopIndex());
}

TEST(SequentialTracer, UncoatedCookeGhostEnergyMatchesTheReferenceMagnitude) {
    // optics.md: all two-bounce ghosts of the uncoated Cooke triplet carry about 2.3 % of the direct
    // image's energy at 550 nm (ray grid over the entrance pupil, on axis).
    optics::Lens lens = optics::loadLens(test::lensPath("cooke-triplet-50mm-f5.lens"));
    for (auto& s : lens.surfaces) s.coatingLayers = 0;
    const LensAtWavelength L(lens, 550.0);
    const double rEP = 0.5 * optics::analyzeFirstOrder(lens, lines::d).entrancePupilDiameter;
    const int N = 64;
    double direct = 0.0, ghosts = 0.0;
    const auto directSteps = pathSteps(lens, std::nullopt);
    std::vector<std::vector<PathStep>> ghostSteps;
    for (const GhostPair& g : enumerateGhosts(lens)) ghostSteps.push_back(pathSteps(lens, g));
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const double x = rEP * (2.0 * (a + 0.5) / N - 1.0), y = rEP * (2.0 * (b + 0.5) / N - 1.0);
            if (x * x + y * y > rEP * rEP) continue;
            const Ray in{{x, y, -1.0}, {0.0, 0.0, 1.0}};
            direct += traceSequential(L, directSteps, in).weight;
            for (const auto& steps : ghostSteps) ghosts += traceSequential(L, steps, in).weight;
        }
    ASSERT_GT(direct, 0.0);
    const double ratio = ghosts / direct;
    std::printf("uncoated Cooke triplet: ghost / direct energy at 550 nm = %.3f %%\n", 100.0 * ratio);
    EXPECT_NEAR(100.0 * ratio, 2.3, 0.15);
}

// Without weights a trace takes the same path to the same fate (Fresnel factors never steer a ray):
// every ray of every Cooke ghost on a tilted grid ends where the weighted trace ends, with weight 1.
TEST(SequentialTracer, UnweightedTracesFollowTheSamePaths) {
    const optics::Lens lens = optics::loadLens(test::lensPath("cooke-triplet-50mm-f5.lens"));
    const LensAtWavelength L(lens, 550.0);
    const glm::dvec3 dir = glm::normalize(glm::dvec3(0.0, 0.25, 1.0));
    int arriving = 0;
    for (const GhostPair& g : enumerateGhosts(lens)) {
        const auto steps = pathSteps(lens, g);
        for (int a = 0; a < 16; ++a)
            for (int b = 0; b < 16; ++b) {
                const Ray in{{-12.0 + 1.5 * a, -12.0 + 1.5 * b, -1.0}, dir};
                const SequentialResult w = traceSequential(L, steps, in);
                const SequentialResult u = traceSequential(L, steps, in, Weighting::None);
                ASSERT_EQ(u.status, w.status) << g.label();
                EXPECT_EQ(u.lostAtStep, w.lostAtStep);
                EXPECT_EQ(u.ray.origin, w.ray.origin);
                if (w.status != RayStatus::Ok) continue;
                EXPECT_EQ(u.weight, 1.0);
                EXPECT_LT(w.weight, 0.1); // two reflections
                ++arriving;
            }
    }
    EXPECT_GT(arriving, 100);
}

// An iris is its own mirror image across a line exactly where every point and its image across the
// line are both inside or both outside: checked on points spread over the circumscribed square, for
// lines at every sixteenth of pi / blades around the circle (on the symmetry lines and between them).
TEST(Iris, MirrorSymmetryLinesAreThoseOfThePolygon) {
    const double pi = std::numbers::pi;
    for (int blades : {0, 5, 6, 9})
        for (double rotation : {0.0, 0.3}) {
            const Iris iris(blades, rotation, 1.0);
            int symmetricLines = 0, lines = 0;
            const int steps = 16 * std::max(blades, 1);
            for (int k = 0; k < steps; ++k) {
                const double line = rotation + k * pi / steps;
                const double cx = std::cos(line), cy = std::sin(line);
                bool mirrored = true;
                for (int j = 0; j < 101 && mirrored; ++j)
                    for (int i = 0; i < 101 && mirrored; ++i) {
                        const double x = -1.3 + 2.6 * (i + 0.37) / 101, y = -1.3 + 2.6 * (j + 0.61) / 101;
                        const double d = x * cx + y * cy; // image: 2 (p . e) e - p
                        mirrored = iris.contains(x, y) == iris.contains(2.0 * d * cx - x, 2.0 * d * cy - y);
                    }
                EXPECT_EQ(iris.mirrorSymmetricAbout(line), mirrored)
                    << blades << " blades, rotation " << rotation << ", line " << line;
                symmetricLines += mirrored;
                ++lines;
            }
            if (blades >= 3)
                EXPECT_EQ(symmetricLines, blades) << blades << " blades: symmetry lines in half a turn";
            else
                EXPECT_EQ(symmetricLines, lines);
        }
}
