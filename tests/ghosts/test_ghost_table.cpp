#include "core/error.h"
#include "core/units.h"
#include "ghosts/ghost_table.h"
#include "ghosts/shaped_cache.h"
#include "ghosts/table_json.h"
#include "optics/lens_loader.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "test_support.h"

using namespace ff;
using namespace ff::ghosts;

namespace {

// A small, fast table: the Cooke triplet (15 ghosts), one wavelength, coarse grid, few angles.
TableSettings small() {
    TableSettings s;
    s.wavelengthsNm = {550.0};
    s.grid = 12;
    s.maxAngles = 13;
    s.maxAngleDeg = 12.0;
    return s;
}

const optics::Lens& cooke() {
    static const optics::Lens lens = optics::loadLens(test::lensPath("cooke-triplet-50mm-f5.lens"));
    return lens;
}

const GhostTable& smallTable() {
    static const GhostTable table = buildGhostTable(cooke(), small());
    return table;
}

} // namespace

TEST(GhostTable, CoversEveryGhostAndInterpolatesThroughItsEntries) {
    const GhostTable& t = smallTable();
    ASSERT_EQ(t.ghosts.size(), 15u);
    // Every ghost keeps the 9 starting angles and refines its own within the budget: 13 per ghost
    // on average.
    EXPECT_LE(t.entryCount(), 13u * t.ghosts.size());
    // The build's report accounts for every trace: each entry was traced once as a starting angle, a
    // mid-angle or a knot's (traced again as a neighbour or a carried piece besides), within the budget.
    const BuildReport& r = t.build;
    EXPECT_EQ(r.budget, 13u * 15u);
    EXPECT_EQ(r.start.traces, 9u * 15u);
    EXPECT_EQ(t.entryCount(), r.start.traces + r.midAngles.traces + r.knots.traces);
    EXPECT_LE(r.traces(), r.budget);
    EXPECT_EQ(r.budgetSpent, r.traces() == r.budget);
    EXPECT_GT(r.rounds, 0u);
    EXPECT_GT(r.start.seconds, 0.0);
    // It names the worst interval: two neighbouring angles of that ghost.
    EXPECT_DOUBLE_EQ(r.worst.error, t.interpolationError);
    const auto named = std::find_if(t.ghosts.begin(), t.ghosts.end(),
                                    [&](const TableGhost& g) { return g.pair.label() == r.worst.ghost; });
    ASSERT_NE(named, t.ghosts.end()) << r.worst.ghost;
    const auto from = std::find(named->anglesDeg.begin(), named->anglesDeg.end(), r.worst.fromDeg);
    ASSERT_NE(from, named->anglesDeg.end());
    ASSERT_NE(from + 1, named->anglesDeg.end());
    EXPECT_EQ(*(from + 1), r.worst.toDeg);
    for (const TableGhost& g : t.ghosts) {
        ASSERT_GE(g.anglesDeg.size(), 9u);
        EXPECT_EQ(g.anglesDeg.front(), 0.0);
        EXPECT_EQ(g.anglesDeg.back(), 12.0);
        EXPECT_TRUE(std::is_sorted(g.anglesDeg.begin(), g.anglesDeg.end()));
        for (int i = 0; i <= 8; ++i) EXPECT_TRUE(std::binary_search(g.anglesDeg.begin(), g.anglesDeg.end(), 1.5 * i));
        // The direct image is traced at every angle of every ghost.
        for (double a : g.anglesDeg) EXPECT_TRUE(std::binary_search(t.anglesDeg.begin(), t.anglesDeg.end(), a));
        ASSERT_EQ(g.entries[0].size(), g.anglesDeg.size());
    }
    EXPECT_TRUE(std::is_sorted(t.anglesDeg.begin(), t.anglesDeg.end()));
    // At a table angle, interpolation returns the entry itself; halfway, the mean of its neighbours.
    const auto& e = t.ghosts[3].entries[0];
    const auto& a = t.ghosts[3].anglesDeg;
    EXPECT_EQ(t.at(3, 0, a[2]).centroidY, e[2].centroidY);
    EXPECT_DOUBLE_EQ(t.at(3, 0, 0.5 * (a[2] + a[3])).sigmaR, 0.5 * (e[2].sigmaR + e[3].sigmaR));
    // The direct image climbs with the angle (+y, azimuth 0) and sits at EFL tan(theta) up to
    // distortion and coma: within 2 % at 12 deg.
    EXPECT_GT(t.directAt(0, 12.0), t.directAt(0, 6.0));
    EXPECT_NEAR(t.directAt(0, 12.0) / (t.efl * std::tan(degToRad(12.0))), 1.0, 0.02);
    // Every fitted profile keeps the ghost's flux: peak x area = flux.
    for (const auto& g : t.ghosts)
        for (const auto& en : g.entries[0]) {
            if (en.flux <= 0.0) continue;
            EXPECT_NEAR(en.gaussian.peak * profileArea(Profile::Gaussian, en.gaussian.widthR, en.gaussian.widthT),
                        en.flux, 1e-9 * en.flux);
        }
}

// A ghost switched on between two angles: between them it keeps the lit end's position and size
// and only its light fades (interpolating towards the dark end's zeros would pull it onto the axis
// and shrink it).
TEST(GhostTable, AGhostSwitchedOnWithinAnIntervalKeepsItsShape) {
    GhostTable t;
    t.wavelengthsNm = {550.0};
    t.anglesDeg = {0.0, 10.0, 20.0};
    t.directY = {{0.0, 8.8, 18.2}};
    TableGhost g;
    g.anglesDeg = t.anglesDeg;
    TableEntry lit;
    lit.centroidY = 12.0;
    lit.sigmaR = 2.0;
    lit.sigmaT = 3.0;
    lit.flux = 1e-4;
    lit.surviving = 0.4;
    lit.gaussian = {2.1, 3.1, 1e-4 / profileArea(Profile::Gaussian, 2.1, 3.1), 0.3};
    lit.cos2 = {5.5, 8.2, 1e-4 / profileArea(Profile::Cos2, 5.5, 8.2), 0.2};
    TableEntry nearAxis = lit;
    nearAxis.flux = 2e-4;
    nearAxis.centroidY = 4.0;
    g.entries = {{nearAxis, lit, TableEntry{}}}; // dark at 20 deg
    t.ghosts.push_back(g);

    const TableEntry e = t.at(0, 0, 17.5); // a quarter of the way from the dark end
    EXPECT_EQ(e.centroidY, 12.0);
    EXPECT_EQ(e.sigmaR, 2.0);
    EXPECT_EQ(e.gaussian.widthT, 3.1);
    EXPECT_EQ(e.cos2.widthR, 5.5);
    EXPECT_DOUBLE_EQ(e.flux, 0.25e-4);
    EXPECT_DOUBLE_EQ(e.surviving, 0.1); // 0.4 faded linearly too
    // The profile still carries exactly the ghost's (faded) flux.
    EXPECT_NEAR(e.gaussian.peak * profileArea(Profile::Gaussian, e.gaussian.widthR, e.gaussian.widthT), e.flux,
                1e-12 * e.flux);
    EXPECT_NEAR(e.cos2.peak * profileArea(Profile::Cos2, e.cos2.widthR, e.cos2.widthT), e.flux, 1e-12 * e.flux);
    EXPECT_DOUBLE_EQ(t.magnification(0, 0, 17.5), 12.0 / (8.8 + 0.75 * (18.2 - 8.8)));
    // Between two lit entries, plain linear interpolation.
    EXPECT_DOUBLE_EQ(t.at(0, 0, 5.0).centroidY, 8.0);
    EXPECT_DOUBLE_EQ(t.at(0, 0, 5.0).flux, 1.5e-4);
}

TEST(GhostTable, JsonRoundTripKeepsEverything) {
    const GhostTable& t = smallTable();
    const GhostTable u = tableFromJson(tableToJson(t), "t.json");
    EXPECT_EQ(u.anglesDeg, t.anglesDeg);
    EXPECT_EQ(u.directY, t.directY);
    EXPECT_EQ(u.lensHash, t.lensHash);
    EXPECT_EQ(u.settingsKey, t.settingsKey);
    ASSERT_EQ(u.ghosts.size(), t.ghosts.size());
    for (std::size_t g = 0; g < t.ghosts.size(); ++g) {
        EXPECT_EQ(u.ghosts[g].pair, t.ghosts[g].pair);
        EXPECT_EQ(u.ghosts[g].anglesDeg, t.ghosts[g].anglesDeg);
        for (std::size_t a = 0; a < t.ghosts[g].anglesDeg.size(); ++a) {
            EXPECT_DOUBLE_EQ(u.ghosts[g].entries[0][a].flux, t.ghosts[g].entries[0][a].flux);
            EXPECT_DOUBLE_EQ(u.ghosts[g].entries[0][a].cos2.widthR, t.ghosts[g].entries[0][a].cos2.widthR);
        }
    }
    // A ghost's angles out of order are refused (interpolation would look in the wrong interval).
    nlohmann::json j = nlohmann::json::parse(tableToJson(t));
    std::swap(j["ghosts"][2]["field_angles_deg"][3], j["ghosts"][2]["field_angles_deg"][4]);
    EXPECT_THROW(tableFromJson(j.dump(), "x.json"), Error);
    EXPECT_THROW(tableFromJson("{\"schema\": \"other\"}", "x.json"), Error);
    EXPECT_THROW(tableFromJson("not json", "x.json"), Error);
}

TEST(GhostTable, CacheHitsMissesAndRebuildsCorruptEntries) {
    test::TempDir dir;
    setenv("FF_CACHE_DIR", dir.path().c_str(), 1);
    CollectingReporter rep;
    bool cached = true;
    const GhostTable first = tableFor(cooke(), small(), true, {}, rep, &cached);
    EXPECT_FALSE(cached); // miss: built and stored
    const auto file = cacheDirectory() / (cacheKey(cooke(), small()) + ".ghosts.json");
    ASSERT_TRUE(std::filesystem::exists(file));
    const GhostTable second = tableFor(cooke(), small(), true, {}, rep, &cached);
    EXPECT_TRUE(cached); // hit
    EXPECT_EQ(second.anglesDeg, first.anglesDeg);
    // Another setting is another key.
    TableSettings other = small();
    other.grid = 10;
    EXPECT_NE(cacheKey(cooke(), other), cacheKey(cooke(), small()));
    // A corrupt entry is rebuilt, with a note, never trusted.
    test::writeFile(file, "{ truncated");
    const GhostTable third = tableFor(cooke(), small(), true, {}, rep, &cached);
    EXPECT_FALSE(cached);
    EXPECT_EQ(third.anglesDeg, first.anglesDeg);
    ASSERT_FALSE(rep.diagnostics.empty());
    EXPECT_NE(rep.diagnostics.back().message.find("rebuilding"), std::string::npos);
    // The rebuilt entry replaced the corrupt one.
    EXPECT_NO_THROW(tableFromJson(test::readFile(file), file.string()));
    unsetenv("FF_CACHE_DIR");
}

// The interpolation target on a lens whose ghosts change smoothly over its field: the Tessar, at the
// default grid and sub-grids, one wavelength. The builder measures its error at the mid-angles it
// traces, which then join the table; here the mid-angle of every final interval of every ghost
// (never traced for that ghost by the builder) is traced directly and compared with the table's
// interpolation, by the builder's measure: centroid relative to max(|centroid|, sigma_r, 1 % of the
// sensor half-height), spreads relative to themselves, where the ghost carries at least 1 % of the
// strongest ghost's flux.
TEST(GhostTable, InterpolatesWithinItsToleranceBetweenEntries) {
    const optics::Lens lens = optics::loadLens(test::lensPath("tessar-100mm-f3.5.lens"));
    TableSettings s;
    s.wavelengthsNm = {550.0};
    const GhostTable t = buildGhostTable(lens, s);
    // Every interval passed: the refinement stopped before its budget.
    EXPECT_LT(t.entryCount(), static_cast<std::size_t>(s.maxAngles) * t.ghosts.size());
    EXPECT_FALSE(t.build.budgetSpent);
    EXPECT_LE(t.interpolationError, s.interpolationTolerance);

    std::vector<double> mids;
    for (const TableGhost& g : t.ghosts)
        for (std::size_t a = 0; a + 1 < g.anglesDeg.size(); ++a)
            mids.push_back(0.5 * (g.anglesDeg[a] + g.anglesDeg[a + 1]));
    std::sort(mids.begin(), mids.end());
    mids.erase(std::unique(mids.begin(), mids.end()), mids.end());
    const auto direct = traceEntries(lens, s, mids);
    ASSERT_EQ(direct.size(), mids.size());
    const double floorMm = 0.01 * 0.5 * t.sensorSizeMm.second;
    double worst = 0.0;
    int compared = 0;
    for (std::size_t g = 0; g < t.ghosts.size(); ++g) {
        const std::vector<double>& own = t.ghosts[g].anglesDeg;
        for (std::size_t a = 0; a + 1 < own.size(); ++a) {
            const double mid = 0.5 * (own[a] + own[a + 1]);
            const std::size_t m =
                static_cast<std::size_t>(std::lower_bound(mids.begin(), mids.end(), mid) - mids.begin());
            double strongest = 0.0;
            for (const auto& other : direct[m]) strongest = std::max(strongest, other[0].flux);
            const TableEntry& d = direct[m][g][0];
            if (d.flux < 0.01 * strongest || d.sigmaR <= 0.0 || d.sigmaT <= 0.0) continue;
            const TableEntry i = t.at(g, 0, mid);
            const double e =
                std::max({std::abs(i.centroidY - d.centroidY) / std::max({std::abs(d.centroidY), d.sigmaR, floorMm}),
                          std::abs(i.sigmaR - d.sigmaR) / d.sigmaR, std::abs(i.sigmaT - d.sigmaT) / d.sigmaT});
            worst = std::max(worst, e);
            ++compared;
            EXPECT_LT(e, s.interpolationTolerance) << t.ghosts[g].pair.label() << " at " << mid << " deg";
        }
    }
    EXPECT_GT(compared, 100);
    std::printf(
        "Tessar, %zu entries (%.1f s): builder's worst %.2f %%; %d ghost entries at fresh mid-angles: worst %.2f %%\n",
        t.entryCount(), t.buildSeconds, 100.0 * t.interpolationError, compared, 100.0 * worst);
}

// The sampling cases (docs/sampling-cases.md): ghosts whose light is thinner than the grid, falls in
// pieces far apart, or steps in weight, at the field angles and wavelengths where a sampling rule was
// needed. What each sweep below checks holds for the lens's true ghost whatever the code: over a
// span of 0.0001 deg its moments change smoothly (even at a square-root kink the mid-angle misses
// the mean of its neighbours by far under the tolerance), so entries a tiny step apart interpolate
// to the one between them within the table's tolerance unless the sampling steps. A brute-force
// reference cannot stand in for the invariant here: plain grids step over the thinnest of this light
// at every density tried (test_table_accuracy.cpp, where the cases a plain grid resolves are checked
// against it).

namespace {

using Entries = std::vector<std::vector<std::vector<TableEntry>>>; ///< traceEntries: [angle][ghost][wavelength]

// The builder's measure of interpolating the first ghost's entry at angle i (wavelength w) from its
// two neighbours, the angles evenly spaced: the centroid relative to max(|centroid|, sigma r, 1 % of
// the sensor half-height), the spreads relative to themselves, each checked against the tolerance;
// the flux relative to itself too where withFlux. Every stride-th interior angle from the second is
// checked. Returns the worst.
double expectMidAnglesWithin(const Entries& e, const std::vector<double>& angles, std::size_t w,
                             const optics::Lens& lens, const TableSettings& s, std::size_t stride,
                             bool withFlux = false) {
    const double floorMm = 0.01 * 0.5 * lens.sensorMm.value_or(s.sensorSizeMm).second;
    double worst = 0.0;
    for (std::size_t i = 1; i + 1 < angles.size(); i += stride) {
        const TableEntry& lo = e[i - 1][0][w];
        const TableEntry& hi = e[i + 1][0][w];
        const TableEntry& mid = e[i][0][w];
        EXPECT_GT(mid.flux, 0.0) << angles[i] << " deg";
        if (mid.flux <= 0.0) continue;
        const double c = std::abs(0.5 * (lo.centroidY + hi.centroidY) - mid.centroidY) /
                         std::max({std::abs(mid.centroidY), mid.sigmaR, floorMm});
        const double r = std::abs(0.5 * (lo.sigmaR + hi.sigmaR) - mid.sigmaR) / mid.sigmaR;
        const double t = std::abs(0.5 * (lo.sigmaT + hi.sigmaT) - mid.sigmaT) / mid.sigmaT;
        const double f = withFlux ? std::abs(0.5 * (lo.flux + hi.flux) - mid.flux) / mid.flux : 0.0;
        EXPECT_LT(std::max({c, r, t, f}), s.interpolationTolerance)
            << angles[i] << " deg: centroid " << c << ", sigma r " << r << ", sigma t " << t << ", flux " << f;
        worst = std::max({worst, c, r, t, f});
    }
    return worst;
}

// One ghost's entries at the default settings, at count + 1 angles from a0, step apart, and the index
// of the wavelength lambdaNm among the table's.
struct Sweep {
    optics::Lens lens;
    TableSettings s;
    const char* label;
    std::vector<double> angles;
    Entries e;
    std::size_t w = 0;
};

Sweep sweep(const char* lensFile, const char* label, double a0, double step, int count, double lambdaNm) {
    Sweep w{optics::loadLens(test::lensPath(lensFile)), TableSettings{}, label, {}, {}};
    for (int i = 0; i <= count; ++i) w.angles.push_back(a0 + step * i);
    const auto at = std::find(w.s.wavelengthsNm.begin(), w.s.wavelengthsNm.end(), lambdaNm);
    if (at == w.s.wavelengthsNm.end()) {
        ADD_FAILURE() << lambdaNm << " nm is not among the table's wavelengths";
        return w; // no entries
    }
    w.w = static_cast<std::size_t>(at - w.s.wavelengthsNm.begin());
    w.e = traceEntries(w.lens, w.s, w.angles, {label});
    EXPECT_EQ(w.e.size(), w.angles.size());
    return w;
}

// expectMidAnglesWithin at every interior angle of the sweep; prints the worst.
void expectSweepWithin(const Sweep& w, bool withFlux = false) {
    if (w.e.size() != w.angles.size()) return; // reported by sweep
    const double worst = expectMidAnglesWithin(w.e, w.angles, w.w, w.lens, w.s, 1, withFlux);
    std::printf("%s at %.6f-%.6f deg, %.0f nm: worst mid-angle error %.3f %%\n", w.label, w.angles.front(),
                w.angles.back(), w.s.wavelengthsNm[w.w], 100.0 * worst);
}

} // namespace

// A ghost whose light falls in pieces far apart: the wide angle's R4->R2 at 31.70-31.80 deg passes a
// disc and, 18 mm from it in the pupil, a band under 0.1 mm thick that carries about a tenth of its
// flux and most of its radial spread. Traced as the table traces it (550 nm, default grid), each
// piece on a grid of its own, its entries at 0.01 deg steps interpolate to their mid-angles within
// the table's tolerance, by the builder's measure; one grid over the square holding both pieces put
// a row or two of rays across the band, and its spreads were off by 2.4 % (radial) and 7.5 %
// (tangential) at such mid-angles.
TEST(GhostTable, AGhostInPiecesFarApartInterpolatesWithinItsTolerance) {
    const optics::Lens lens = optics::loadLens(test::lensPath("wide-angle-16.7mm-f4.lens"));
    TableSettings s;
    s.wavelengthsNm = {550.0};
    std::vector<double> angles;
    for (int i = 0; i <= 20; ++i) angles.push_back(31.70 + 0.005 * i);
    const auto e = traceEntries(lens, s, angles, {"R4\u2192R2"});
    ASSERT_EQ(e.size(), angles.size());
    for (std::size_t i = 1; i + 1 < angles.size(); i += 2) {
        // The band lands about 16 mm from the disc on the sensor: with a share f of the flux it alone
        // gives sigma r about 16 mm x sqrt(f (1 - f)), 4 mm for f = 0.07; the disc's own is 0.2 mm.
        ASSERT_GT(e[i][0][0].sigmaR, 3.0) << angles[i] << " deg: the band's light should be counted";
    }
    const double worst = expectMidAnglesWithin(e, angles, 0, lens, s, 2);
    std::printf("R4->R2 at 31.70-31.80 deg: worst mid-angle error %.3f %%\n", 100.0 * worst);
    EXPECT_THROW(traceEntries(lens, s, {31.7}, {"R9\u2192R8 (no such ghost)"}), Error);
}

// A ghost whose light falls in pieces far apart across a gap narrower than the larger piece is long:
// the double Gauss 50 mm's R3->R1 at 21.8404-21.8408 deg and 450 nm passes a crescent 20 x 8 mm and,
// 7.6 mm below it, a patch 0.6 x 0.3 mm whose light lands 17 mm from the ghost's centroid (about 7 %
// of its radial second moment). Each gets a square of its own, slid apart along the gap
// (trace::pupilParts); one square over both put the 32 grid's rays 0.67 mm apart over the patch,
// which fell between them from 21.8407 deg on, and sigma r stepped by 7 % there (its mid-angle missed
// by 3.7 %). Entries 0.0001 deg apart interpolate to their mid-angles within the table's tolerance,
// by the builder's measure.
TEST(GhostTable, APatchBesideALongPieceInterpolatesWithinItsTolerance) {
    expectSweepWithin(sweep("double-gauss-50mm-f2.lens", "R3\u2192R1", 21.8404, 0.0001, 4, 450.0));
}

// Light thinner than the grid at the tip of a sliver: the telephoto's R8->R3 at 6.657 deg and 650 nm
// is a focused ghost (sigma t 0.125 mm) whose light tapers, at both ends along x, into tips that pass
// between all five rays of the outermost cells of its square; as the field angle moved the square
// (its half side 7.200 mm at 6.65706 deg, 6.975 mm from 6.65710 deg) the tips fell in and out of the
// centre-and-corner rays, and sigma t stepped by 1.6 % (its mid-angle missed by 0.8 %). Dark cells
// into which a traced sub-grid's light reaches are traced on sub-grids too
// (trace::measureBundleResolved). Entries 0.0000385 deg apart (the table's finest step on this lens)
// interpolate to their mid-angles within the table's tolerance.
TEST(GhostTable, TheTipOfASliverBetweenTheRaysInterpolatesWithinItsTolerance) {
    expectSweepWithin(sweep("telephoto-127mm-f5.6.lens", "R8\u2192R3", 6.657019, 0.0000385, 4, 650.0));
}

// A step in the rays' weight: the double Gauss 50 mm's R11->R7 at 0.411 deg and 450 nm, a ghost
// spread over 26 mm whose weight rises six-fold across a line of its pupil (a reflection turning
// total), so that cells all of whose five rays arrive hold both sides of the step. Integrated by
// their centre and corner rays, such cells moved the ghost's flux by 3.2 % and its centroid by
// 0.66 mm within 0.00005 deg as the square moved with the field angle (its mid-angle missed by
// 1.6 %); re-traced on sub-grids, entries 0.000047 deg apart (the table's finest step on this lens
// is 0.00019 deg) interpolate to their mid-angles within the table's tolerance, by the builder's
// measure and in flux.
TEST(GhostTable, AStepInTheRaysWeightInterpolatesWithinItsTolerance) {
    expectSweepWithin(sweep("double-gauss-50mm-f2.lens", "R11\u2192R7", 0.41096, 0.000047, 4, 450.0), true);
}

// Light far from the rest that no straddling cell borders: the zoom's R9->R3 at 13.1513-13.1517 deg
// and 450 nm passes a disc and, 14 mm from it in the pupil, two slivers 0.7 mm wide whose light lands
// 17 mm from the ghost's centroid. One square over all of it put the 32 grid's rays 1.3 mm apart over
// the slivers, which fell between every ray from 13.1515 deg on: sigma r dropped from 3.67 to 2.52 mm
// within 0.0001 deg (its mid-angle missed by 16 %). The region search's local passes, twice as
// dense, found them; the dark cells holding their lit points are traced on sub-grids
// (trace::measureBundleResolved). Entries 0.0001 deg apart (the table's finest step on this lens is
// 0.000136 deg) interpolate to their mid-angles within the table's tolerance, by the builder's measure.
TEST(GhostTable, SliversBetweenTheRaysThatTheSearchFoundInterpolateWithinTheirTolerance) {
    const Sweep w = sweep("zoom-70-200mm-f2.8.lens", "R9\u2192R3", 13.1513, 0.0001, 4, 450.0);
    for (std::size_t i = 0; i < w.e.size(); ++i) {
        // The slivers carry about 2 % of the flux 17 mm from the centroid: sigma r^2 gains about
        // 0.02 x 17^2 = 6 mm^2 over the disc's own (2.5 mm)^2, so sigma r is near 3.6 mm with them.
        EXPECT_GT(w.e[i][0][w.w].sigmaR, 3.3) << w.angles[i] << " deg: the slivers' light should be counted";
    }
    expectSweepWithin(w);
}

// A patch smaller than both the grid's cells and the local passes' spacing: the wide angle's R8->R4 at
// 4.4850-4.4852 deg and 550 nm passes, besides its ring, a patch 0.2 x 0.1 mm of the pupil whose light
// lands 3.9 mm from the centroid (0.1 % of the flux, a tenth of sigma r^2) until it vanishes near
// 4.4855 deg. The 32 grid's rays, 0.43 mm apart, and the last local pass, 0.21 mm apart, stepped over
// it from 4.4851 deg on (sigma r dropped from 0.395 to 0.364 mm there, its mid-angle missed by 4 %);
// the search's jittered coarse pass met it, and the dark cell holding that lit point is traced on a
// sub-grid. Entries 0.00005 deg apart (the table's finest step on this lens is 0.00041 deg)
// interpolate to their mid-angles within the table's tolerance, by the builder's measure.
TEST(GhostTable, APatchOnlyTheCoarsePassMetInterpolatesWithinItsTolerance) {
    expectSweepWithin(sweep("wide-angle-16.7mm-f4.lens", "R8\u2192R4", 4.48505, 0.00005, 4, 550.0));
}

// Light in a dark cell is thin (it passed between rays a cell apart), so such cells are traced on
// sub-grids twice as dense as the straddling cells'. The double Gauss 50 mm's R11->R5 at 24.6897-
// 24.6901 deg and 450 nm is thin light on a 256 grid; counting whole sub-cells of 8 x 8 sub-grids,
// its dark cells' light moved sigma r by 2.6 % within 0.0001 deg at 24.6899 deg (its mid-angle
// missed by 1.2 %), on 16 x 16 by a third of that, and sigma r stayed 2 % below a 512 grid's (a band
// thinner still, below). With each sub-cell's lit share (trace/open_trace.h) the entries 0.0001 deg
// apart (the table's finest step on this lens is 0.00019 deg) interpolate to their mid-angles within
// the table's tolerance.
TEST(GhostTable, ThinLightInDarkCellsInterpolatesWithinItsTolerance) {
    expectSweepWithin(sweep("double-gauss-50mm-f2.lens", "R11\u2192R5", 24.6897, 0.0001, 4, 450.0));
}

// The counting circle along a row of cells: the zoom's R32->R26 at 10.0705 deg and 650 nm lands as a
// line 42 mm out (sigma t 3.4 mm, sigma r 0.68 mm) whose distance from the axis varies with the
// pupil's y alone, so the circle within which light counts (43.3 mm, the sensor's diagonal) crosses
// its pupil along a row, through 24 cells of the 32 grid at once. Their sub-grids counted whole
// sub-cells, all erring alike, and as the square moved with the field angle (half side 10.50 mm to
// 10.21 mm at 10.07056 deg) the flux stepped by 1.6 % and sigma r by 1.5 % (its mid-angle missed by
// 0.8 %). Each sub-cell now counts the share of it inside the circle (trace::measureBundleResolved):
// entries 0.00002 deg apart (the table's finest step on this lens is 0.000136 deg) interpolate to
// their mid-angles within the table's tolerance, by the builder's measure and in flux.
TEST(GhostTable, LightCutByTheCountingCircleAlongARowInterpolatesWithinItsTolerance) {
    expectSweepWithin(sweep("zoom-70-200mm-f2.8.lens", "R32\u2192R26", 10.07052, 0.00002, 4, 650.0), true);
}

// A band of light thinner than the sub-grids, far from the rest: the double Gauss 50 mm's R11->R5 at
// 24.6888 deg and 450 nm passes, besides its main light, a band 5 um thick and 0.12 mm long between
// the front lens's rim and the last surface's, whose light lands 3 mm from the centroid (5 % of
// sigma r^2). Dark cells holding it were resolved only where the region search had met it, and the
// 16 x 16 sub-grids then used (4.6 um apart) put zero, one or two rows across it: sigma r stepped by
// 1.2 % within 0.00003 deg (its mid-angle missed by 0.61 %). Dark cells whose rays' open traces
// leave room for light between two edges are now resolved, and each sub-cell counts its lit share
// (trace/open_trace.h): entries 0.00003 deg apart interpolate to their mid-angles within the table's
// tolerance, by the builder's measure.
TEST(GhostTable, ABandThinnerThanTheSubGridsInterpolatesWithinItsTolerance) {
    expectSweepWithin(sweep("double-gauss-50mm-f2.lens", "R11\u2192R5", 24.68876, 0.00003, 4, 450.0));
}

// A step in the weight beside a vignetting edge: the double Gauss 50 mm's R11->R7 at 13.1127 deg and
// 650 nm has its weight step (a reflection turning total) along the border between the outermost
// columns of its square's cells, where the front lens's rim cuts its light. The cells of the outer
// column straddle the rim; none of their arriving rays lies beyond the step, so their 4 x 4 sub-grids
// counted the step's light at the wrong weight, and the flux stepped by 1.7 % within 0.00002 deg as
// the square moved (its mid-angle missed by 0.8 %). Straddling cells beside a cell whose rays show
// a step are resolved as densely as that cell (trace::measureBundleResolved): entries 0.00003 deg
// apart interpolate to their mid-angles within the table's tolerance, by the builder's measure and
// in flux.
TEST(GhostTable, AStepInTheWeightBesideAnEdgeInterpolatesWithinItsTolerance) {
    expectSweepWithin(sweep("double-gauss-50mm-f2.lens", "R11\u2192R7", 13.11266, 0.00003, 4, 650.0), true);
}

// A lit share where the margins are far from linear: the wide angle's R17->R16 at 45.03 deg and
// 550 nm, a haze 11 mm wide reaching the counting circle, has sub-cells near a fold of its landing
// map, where the landing point's distance from the circle changes so fast across a sub-cell that
// its linear model gave a lit part where there is none: a ray of it landed 510 mm out, 0.0006 % of
// the flux carrying 4 % of sigma r^2, and sigma r jumped from 11.18 to 11.66 mm and back within
// 0.02 deg. The ray traced for a sub-cell's lit part must land within the circle, or the share is
// 0 (trace::traceSubGrids): entries 0.005 deg apart interpolate to their mid-angles within the
// table's tolerance, by the builder's measure.
TEST(GhostTable, ALitShareAtAFoldOfTheLandingMapInterpolatesWithinItsTolerance) {
    expectSweepWithin(sweep("wide-angle-16.7mm-f4.lens", "R17\u2192R16", 45.02, 0.005, 4, 550.0));
}
