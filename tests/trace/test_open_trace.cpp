// Open traces (every aperture open, with each step's margin inside its aperture) and the lit share
// of a cell from its margins, against the analytic tracer and against areas computed by hand.

#include "core/units.h"
#include "trace/aperture.h"
#include "trace/ghost_path.h"
#include "trace/open_trace.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lens_bench.h"

using namespace ff;
using namespace ff::trace;
using test::LensBench;

TEST(OpenTrace, FeasibleShareIsTheAreaOfTheClippedSquare) {
    EXPECT_DOUBLE_EQ(feasibleShare({}), 1.0);
    // Half-planes through the centre keep half the square whatever their direction.
    EXPECT_NEAR(feasibleShare(std::vector<HalfPlane>{{0.0, 1.0, 0.0}}), 0.5, 1e-15);
    EXPECT_NEAR(feasibleShare(std::vector<HalfPlane>{{0.0, 0.6, -0.8}}), 0.5, 1e-15);
    // u + v >= 1/2: the triangle (1/2, 0), (1/2, 1/2), (0, 1/2), area 1/8.
    EXPECT_NEAR(feasibleShare(std::vector<HalfPlane>{{-0.5, 1.0, 1.0}}), 0.125, 1e-15);
    // A strip 0.1 <= v <= 0.13 (two margins, each negative on the other's side): 0.03 of the square.
    EXPECT_NEAR(feasibleShare(std::vector<HalfPlane>{{-0.1, 0.0, 1.0}, {0.13, 0.0, -1.0}}), 0.03, 1e-15);
    // The same strip beyond the square, and a half-plane missing it.
    EXPECT_EQ(feasibleShare(std::vector<HalfPlane>{{-0.7, 0.0, 1.0}, {0.73, 0.0, -1.0}}), 0.0);
    EXPECT_EQ(feasibleShare(std::vector<HalfPlane>{{-2.0, 1.0, 1.0}}), 0.0);
    EXPECT_DOUBLE_EQ(feasibleShare(std::vector<HalfPlane>{{2.0, 1.0, 1.0}}), 1.0);
}

TEST(OpenTrace, IrisMarginIsTheDistanceToTheNearestEdge) {
    const Iris circle(0, 0.0, 4.0);
    EXPECT_DOUBLE_EQ(circle.margin(3.0, 0.0), 1.0);
    EXPECT_DOUBLE_EQ(circle.margin(3.0, 4.0), -1.0);
    const Iris hexagon(6, 0.3, 4.0);
    const double sector = std::numbers::pi / 3.0, inradius = hexagon.circumradius * std::cos(0.5 * sector);
    EXPECT_NEAR(hexagon.margin(0.0, 0.0), inradius, 1e-12);
    // An edge's midpoint lies along its normal, half a sector from the first vertex; the vertex on two edges.
    const double normal = 0.3 + 0.5 * sector;
    EXPECT_NEAR(hexagon.margin(inradius * std::cos(normal), inradius * std::sin(normal)), 0.0, 1e-12);
    EXPECT_NEAR(hexagon.margin(hexagon.circumradius * std::cos(0.3), hexagon.circumradius * std::sin(0.3)), 0.0, 1e-12);
    // 0.5 mm outward from the midpoint along the normal.
    EXPECT_NEAR(hexagon.margin((inradius + 0.5) * std::cos(normal), (inradius + 0.5) * std::sin(normal)), -0.5, 1e-12);
    int disagreements = 0;
    for (int i = 0; i < 200; ++i)
        for (int j = 0; j < 200; ++j) {
            const double x = -6.0 + 0.06 * i, y = -6.0 + 0.06 * j, m = hexagon.margin(x, y);
            if (std::abs(m) > 1e-9 && (m > 0.0) != hexagon.contains(x, y)) ++disagreements;
        }
    EXPECT_EQ(disagreements, 0);
}

// The open trace of a ray the analytic tracer passes is that ray's trace, every margin non-negative;
// of a ray it clips at step k, the margin there is negative and those before are not.
TEST(OpenTrace, AgreesWithTheAnalyticTracerAndItsClipping) {
    const LensBench s("double-gauss-50mm-f2.lens");
    const Field field{degToRad(20.0), 0.0};
    int ok = 0, clipped = 0;
    for (const GhostPair& g : enumerateGhosts(s.lens)) {
        if (g.label() != "R11\u2192R5" && g.label() != "R3\u2192R1") continue;
        const auto steps = pathSteps(s.lens, g);
        const Bundle b = gridBundle(s.pupil, field, 48, 0.0, 0.0, 14.0, false);
        const OpenTrace open = traceOpen(s.L, steps, b.rays);
        ASSERT_EQ(open.hits.size(), b.rays.size());
        for (std::size_t i = 0; i < b.rays.size(); ++i) {
            const SequentialResult ref = traceSequential(s.L, steps, b.rays[i]);
            if (ref.status == optics::RayStatus::Ok) {
                ++ok;
                ASSERT_EQ(open.hits[i].status, optics::RayStatus::Ok);
                EXPECT_NEAR(open.hits[i].sensorPoint.x, ref.ray.origin.x, 1e-9);
                EXPECT_NEAR(open.hits[i].sensorPoint.y, ref.ray.origin.y, 1e-9);
                EXPECT_NEAR(open.hits[i].weight, ref.weight, 1e-15);
                for (std::size_t k = 0; k < steps.size(); ++k)
                    EXPECT_GE(open.margin(i, k), 0.0) << g.label() << " step " << k;
            } else if (ref.status == optics::RayStatus::Clipped) {
                ++clipped;
                EXPECT_LT(open.margin(i, ref.lostAtStep), 0.0) << g.label() << " ray " << i;
                for (std::size_t k = 0; k < ref.lostAtStep; ++k)
                    EXPECT_GE(open.margin(i, k), 0.0) << g.label() << " step " << k;
            }
        }
    }
    EXPECT_GT(ok, 50);
    EXPECT_GT(clipped, 50);
}

namespace {

// An open trace of a sub x sub grid whose margins are given functions of the sub-ray's place (u, v,
// in sub-cells from the grid's corner), all rays arriving at the origin.
template <class... M>
OpenTrace syntheticGrid(int sub, M... margins) {
    OpenTrace t;
    t.steps = sizeof...(M);
    t.hits.resize(static_cast<std::size_t>(sub) * sub);
    for (int j = 0; j < sub; ++j)
        for (int i = 0; i < sub; ++i) {
            const double u = i + 0.5, v = j + 0.5;
            for (const double m : {margins(u, v)...}) t.margins.push_back(m);
        }
    return t;
}

double sum(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return s;
}

} // namespace

// Straight edges over an 8 x 8 sub-grid: the shares add up to the lit area in sub-cells, where
// counting whole sub-cells by their centres gives whole columns or rows.
TEST(OpenTrace, SubCellSharesAddUpToTheLitArea) {
    // An edge at u = 3.3, tilted by 0.3 per sub-cell (lit where u <= 3.3 + 0.3 (v - 4)): 8 x 3.3.
    const OpenTrace tilted = syntheticGrid(8, [](double u, double v) { return 3.3 + 0.3 * (v - 4.0) - u; });
    EXPECT_NEAR(sum(subCellShares(tilted, 0, 8, 0.0)), 26.4, 1e-9);
    // A band 0.05 sub-cells thick at v = 3.62-3.67 between two edges, passing between every centre.
    const OpenTrace band = syntheticGrid(
        8, [](double, double v) { return v - 3.62; }, [](double, double v) { return 3.67 - v; });
    const std::vector<double> shares = subCellShares(band, 0, 8, 0.0);
    EXPECT_NEAR(sum(shares), 8 * 0.05, 1e-9);
    for (int i = 0; i < 8; ++i) EXPECT_NEAR(shares[3 * 8 + i], 0.05, 1e-9);
    // The counting circle is one more margin: rays landing at x = u - 4 mm, circle of radius 2.5 mm
    // (a chord of the grid: lit where |u - 4| <= 2.5 along every row).
    OpenTrace landing = syntheticGrid(8, [](double, double) { return 1.0; });
    for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i)
            landing.hits[static_cast<std::size_t>(j) * 8 + i].sensorPoint = glm::dvec3(i + 0.5 - 4.0, 0.0, 0.0);
    EXPECT_NEAR(sum(subCellShares(landing, 0, 8, 2.5)), 8 * 5.0, 1e-9);
}

// A cell whose five rays are all dark on either side of a band passing between them may hold light;
// the same band beyond the cell may not.
TEST(OpenTrace, ACellMayHoldABandBetweenItsRays) {
    // The heights of the rays at the centre and corners (-,-), (+,-), (-,+), (+,+), in cells.
    const double v[5] = {0.0, -0.5, -0.5, 0.5, 0.5};
    auto five = [&](double lo, double hi) {
        OpenTrace t;
        t.steps = 2;
        t.hits.resize(5);
        for (int r = 0; r < 5; ++r) t.margins.insert(t.margins.end(), {v[r] - lo, hi - v[r]});
        return t;
    };
    const OpenTrace inside = five(0.1, 0.15), beyond = five(0.7, 0.75);
    for (std::size_t r = 0; r < 5; ++r)
        EXPECT_LT(std::min(inside.margin(r, 0), inside.margin(r, 1)), 0.0) << "ray " << r << " is dark";
    EXPECT_TRUE(mayHoldLight(inside, 0, 0.0));
    EXPECT_FALSE(mayHoldLight(beyond, 0, 0.0));
}
