#include "ghosts/ghost_table.h"
#include "ghosts/table_refinement.h"
#include "optics/lens_loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "test_support.h"

using namespace ff::ghosts;

namespace {

// One wavelength's entries of a ghost at angles 5.0, 5.1, 5.2, 5.3 deg, whose light holds a far
// piece with flux falling linearly to zero at `vanishes` deg: with flux share f at distance d from the
// centroid, the piece adds f d^2 to the radial second moment, so sigma r^2 = base + slope x (vanishes
// - a) before and base after. The centroid moves linearly (its shift by the piece left out: the
// lines through it agree), sigma t stays.
GhostNodes vanishingPiece(double vanishes) {
    GhostNodes n;
    for (int i = 0; i < 4; ++i) {
        const double a = 5.0 + 0.1 * i;
        TableEntry e;
        e.flux = 1e-4;
        e.centroidY = 2.5 + 0.1 * (a - 5.0);
        e.sigmaR = std::sqrt(0.025 + 0.4 * std::max(0.0, vanishes - a));
        e.sigmaT = 0.25;
        n.angles.push_back(a);
        n.rows.push_back({e});
    }
    return n;
}

} // namespace

// The knot of a failing interval at the finest step goes where the second moment's two lines meet:
// exactly at the angle where the piece vanishes, wherever in the interval that is. (The widths' own
// lines, bent by the square root, would meet at 5.1499 deg for 5.137: sigma r 0.2825, 0.1995 at 5.0,
// 5.1 deg, slope -0.830 per deg, reaching 0.1581 at 5.1 + 0.0414 / 0.830.)
TEST(TableRefinement, AKnotGoesWhereAFarPieceVanishes) {
    for (const double vanishes : {5.137, 5.112, 5.188}) {
        const GhostNodes n = vanishingPiece(vanishes);
        EXPECT_NEAR(kinkAngle(n, 1, {1e-4}, 0.12), vanishes, 1e-9);
    }
}

// Where the entries beside the interval are missing, dark, or their lines meet outside it (here
// all on one line: no kink), the knot is the mid-angle.
TEST(TableRefinement, AKnotFallsBackToTheMidAngle) {
    const GhostNodes kinked = vanishingPiece(5.137);
    EXPECT_DOUBLE_EQ(kinkAngle(kinked, 0, {1e-4}, 0.12), 5.05); // no entry before the first
    EXPECT_DOUBLE_EQ(kinkAngle(kinked, 2, {1e-4}, 0.12), 5.25); // none after the last
    GhostNodes dark = kinked;
    dark.rows[3][0] = TableEntry{};
    EXPECT_DOUBLE_EQ(kinkAngle(dark, 1, {1e-4}, 0.12), 5.15);
    const GhostNodes straight = vanishingPiece(6.0); // the piece stays through all four angles
    EXPECT_DOUBLE_EQ(kinkAngle(straight, 1, {1e-4}, 0.12), 5.15);
    // A ghost under 1 % of the strongest there is not followed.
    EXPECT_DOUBLE_EQ(kinkAngle(kinked, 1, {1.0}, 0.12), 5.15);
}

// The error of interpolating at a fraction of an interval: none for entries on one line, and for a
// spread off by 2 % at the quarter-angle, 2 % relative to the entry's own.
TEST(TableRefinement, MidErrorAtAFractionOfTheInterval) {
    const GhostNodes n = vanishingPiece(6.0);
    std::vector<TableEntry> quarter = {n.rows[1][0]};
    quarter[0].centroidY = 0.75 * n.rows[1][0].centroidY + 0.25 * n.rows[2][0].centroidY;
    quarter[0].sigmaR = 0.75 * n.rows[1][0].sigmaR + 0.25 * n.rows[2][0].sigmaR;
    auto [e, relevant] = midError(n.rows[1], n.rows[2], quarter, 0.25, {1e-4}, 0.12);
    EXPECT_TRUE(relevant);
    EXPECT_NEAR(e, 0.0, 1e-12);
    const double exact = quarter[0].sigmaR;
    quarter[0].sigmaR = exact / 1.02;
    std::tie(e, relevant) = midError(n.rows[1], n.rows[2], quarter, 0.25, {1e-4}, 0.12);
    EXPECT_NEAR(e, 0.02, 1e-9);
}

// A ghost with a failing interval at the finest step is traced again on a grid twice as fine: each of
// its entries (here the Cooke triplet's ghost whose radial spread at 550 nm differs most between an
// 8 and a 16 grid) moves to what a table with a 16 grid traces there, every interval waits to be measured
// again (at the finest step too), and the ghost is not refined past kMaxGridScale nor past the budget.
TEST(TableRefinement, AGhostFailingAtTheFinestStepIsTracedOnAFinerGrid) {
    const ff::optics::Lens lens = ff::optics::loadLens(ff::test::lensPath("cooke-triplet-50mm-f5.lens"));
    TableSettings coarse;
    coarse.wavelengthsNm = {550.0};
    coarse.grid = 8;
    TableSettings fine = coarse;
    fine.grid = 16;
    const std::vector<double> angles = {6.0, 6.001, 6.002};
    const std::vector<std::vector<std::vector<TableEntry>>> atFine = traceEntries(lens, fine, angles);
    const std::vector<std::vector<std::vector<TableEntry>>> atCoarse = traceEntries(lens, coarse, angles);
    std::size_t ghost = 0;
    double most = 0.0;
    for (std::size_t g = 0; g < atFine[1].size(); ++g) {
        const TableEntry &c = atCoarse[1][g][0], &f = atFine[1][g][0];
        if (f.flux <= 0.0 || f.sigmaR <= 0.0) continue;
        if (const double d = std::abs(c.sigmaR / f.sigmaR - 1.0); d > most) most = d, ghost = g;
    }

    const Progress none;
    EntryTracer tracer(lens, coarse, none);
    const std::size_t nG = tracer.pairs().size();
    std::vector<Task> tasks;
    for (const double a : angles) tasks.push_back({ghost, a, {}});
    Traced traced = tracer.trace(tasks);
    std::vector<GhostNodes> nodes(nG);
    GhostNodes& n = nodes[ghost];
    n.angles = angles;
    n.rows = traced.rows;
    n.found = traced.found;
    n.intervals.assign(2, Interval{true, true, 0.001});
    n.intervals[1].error = 0.02; // failing, at the finest step
    RefinementLimits limits{0.005, 0.0015, 0.0, 100};
    // The coarse grid's error is well over the agreement asked of the finer one below.
    const double coarseSigmaR = n.rows[1][0].sigmaR, fineSigmaR = atFine[1][ghost][0].sigmaR;
    ASSERT_GT(std::abs(coarseSigmaR - fineSigmaR), 0.002 * fineSigmaR);

    // Not within the budget: nothing traced.
    std::size_t spent = 98;
    EXPECT_FALSE(traceFiner(tracer, nodes, limits, spent));
    EXPECT_EQ(spent, 98u);
    EXPECT_EQ(n.gridScale, 1);

    spent = 10;
    EXPECT_TRUE(traceFiner(tracer, nodes, limits, spent));
    EXPECT_EQ(spent, 13u);
    EXPECT_EQ(n.gridScale, 2);
    for (std::size_t a = 0; a < angles.size(); ++a) {
        const TableEntry &got = n.rows[a][0], &want = atFine[a][ghost][0];
        EXPECT_NEAR(got.sigmaR, want.sigmaR, 1e-3 * want.sigmaR) << angles[a];
        EXPECT_NEAR(got.sigmaT, want.sigmaT, 1e-3 * want.sigmaT) << angles[a];
        EXPECT_NEAR(got.centroidY, want.centroidY, 1e-3 * std::abs(want.centroidY)) << angles[a];
        EXPECT_NEAR(got.flux, want.flux, 1e-3 * want.flux) << angles[a];
    }
    for (const Interval& v : n.intervals) {
        EXPECT_FALSE(v.measured);
        EXPECT_TRUE(v.remeasure);
    }
    // Still failing, but at kMaxGridScale: not traced again.
    static_assert(kMaxGridScale == 2);
    n.intervals[1].error = 0.02;
    EXPECT_FALSE(traceFiner(tracer, nodes, limits, spent));
    EXPECT_EQ(spent, 13u);
}
