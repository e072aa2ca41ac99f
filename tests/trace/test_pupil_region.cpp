// Where the pupil-region search puts a path's grid, and what it measures of the light there, each
// against an analytic pass of its own: that the region holds all of the path's light, the share of
// its square that is lit, and the share of the light too thin for the search's points.

#include "core/units.h"
#include "trace/ghost_path.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <tuple>

#include "lens_bench.h"
#include "pupil_passes.h"

using namespace ff;
using namespace ff::trace;
using test::coverage;
using test::Coverage;
using test::kScanPoints;
using test::LensBench;
using test::scanLine;
using test::stepsOf;

// The region's lit fraction (estimated on its 64 x 64 analytic pass) is the share of its square whose
// rays arrive, counted here on a 256 x 256 grid by the same analytic tracer, for every ghost of the
// Cooke triplet at 0, 14 and 24 deg and of the double Gauss 50 mm at 24.6 deg: discs, vignetted
// cat's eyes and slivers (ghosts nearly vignetted away, for which the ghost table refines its grid).
TEST(PupilRegion, LitFractionIsTheShareOfItsSquareThatArrives) {
    const LensBench cooke("cooke-triplet-50mm-f5.lens"), gauss("double-gauss-50mm-f2.lens");
    const std::pair<const LensBench*, double> cases[] = {{&cooke, 0.0}, {&cooke, 14.0}, {&cooke, 24.0}, {&gauss, 24.6}};
    int checked = 0;
    double lowest = 1.0, worst = 0.0;
    for (const auto& [bench, angle] : cases) {
        const LensBench& s = *bench;
        const Field field{degToRad(angle), 0.0};
        for (const GhostPair& g : enumerateGhosts(s.lens)) {
            const auto steps = pathSteps(s.lens, g);
            const PupilRegion region = pupilRegion(s.pupil, field, Sampling::Reaim, s.L, steps);
            const Bundle b = regionBundle(s.pupil, field, region, 256);
            std::vector<RayResult> hits(b.rays.size());
            traceAnalytic(s.L, steps, b.rays, hits);
            const double arriving =
                double(std::count_if(hits.begin(), hits.end(),
                                     [](const RayResult& r) { return r.status == optics::RayStatus::Ok; })) /
                double(hits.size());
            if (arriving == 0.0) continue;
            // 64 points per side, over a square about as wide as the region: a shape of perimeter P is
            // off by about P x cell / 2 where its edges fall on the points, with random signs along it.
            EXPECT_NEAR(region.litFraction, arriving, 0.01) << g.label() << " at " << angle << " deg";
            worst = std::max(worst, std::abs(region.litFraction - arriving));
            lowest = std::min(lowest, arriving);
            ++checked;
        }
    }
    EXPECT_GE(checked, 60);
    EXPECT_LT(lowest, 0.1);
    std::printf("%d regions checked; the thinnest passes %.3f of its square; worst difference %.4f\n", checked, lowest,
                worst);
}

// The region holds every point of the pupil plane whose ray arrives, found here by a 768 x 768
// analytic pass over the whole square the search starts from (spacing 0.14 mm). The wide angle's
// front opening (47.5 mm) dwarfs its entrance pupil (2.1 mm): its R2->R1, R3->R2 and R5->R4 pass
// patches under a millimetre across, and its R4->R2 a disc and a ring or arcs 11 mm out and 0.2-0.3 mm
// wide, which a search with a fixed 96 x 96 first pass (1.1 mm apart) stepped over in 15 of these 24
// cases (missing all the light in 11).
TEST(PupilRegion, HoldsEveryPointWhoseRayArrives) {
    const LensBench s("wide-angle-16.7mm-f4.lens");
    std::map<std::string, std::vector<PathStep>> paths;
    for (const GhostPair& g : enumerateGhosts(s.lens)) paths[g.label()] = pathSteps(s.lens, g);
    int checked = 0;
    for (const char* label : {"R2\u2192R1", "R3\u2192R2", "R4\u2192R2", "R5\u2192R4"})
        for (double angle : {3.909, 6.0, 12.0, 22.0, 30.0, 44.0}) {
            const auto& steps = paths.at(label);
            const Field field{degToRad(angle), 0.0};
            const PupilRegion region = pupilRegion(s.pupil, field, Sampling::Reaim, s.L, steps);
            const Coverage c = coverage(s, s.L, steps, field, {region});
            EXPECT_EQ(c.outside[0], 0) << label << " at " << angle << " deg: " << c.outside[0] << " of " << c.lit
                                       << " arriving points outside";
            checked += c.lit > 0;
        }
    EXPECT_GE(checked, 20);
}

// With a counting radius the region holds the light that lands within it, and its lit fraction is that
// light's share of its square. The telephoto's R7->R5 at 9.9 deg lands 41-68 mm from the axis; only a
// sliver of it (the pupil's lower edge) lands within the 43.27 mm the ghost table counts, and a grid
// over the whole ghost's light would put one or two rows across it.
TEST(PupilRegion, WithACountingRadiusHoldsTheLightLandingWithinIt) {
    const LensBench s("telephoto-127mm-f5.6.lens");
    const std::vector<PathStep> steps = stepsOf(s.lens, "R7\u2192R5");
    ASSERT_FALSE(steps.empty());
    const auto within = [](const RayResult& r) {
        return r.status == optics::RayStatus::Ok && std::hypot(r.sensorPoint.x, r.sensorPoint.y) <= test::kMaxRadius;
    };
    for (double angle : {9.88, 9.9, 9.92}) {
        const Field field{degToRad(angle), 0.0};
        const PupilRegion all = pupilRegion(s.pupil, field, Sampling::Reaim, s.L, steps);
        const PupilRegion region = pupilRegion(s.pupil, field, Sampling::Reaim, s.L, steps, test::kMaxRadius);
        const Coverage c = coverage(s, s.L, steps, field, {region}, test::kMaxRadius);
        ASSERT_GT(c.lit, 0);
        EXPECT_EQ(c.outside[0], 0) << angle << " deg: " << c.outside[0] << " of " << c.lit
                                   << " points landing within the radius outside";
        const Bundle b = regionBundle(s.pupil, field, region, 256);
        std::vector<RayResult> own(b.rays.size());
        traceAnalytic(s.L, steps, b.rays, own);
        const double share = double(std::count_if(own.begin(), own.end(), within)) / double(own.size());
        EXPECT_NEAR(region.litFraction, share, 0.01) << angle << " deg";
        EXPECT_LT(share, 0.25 * all.litFraction) << angle << " deg";
        std::printf("%.2f deg: %.3f of the region lands within the radius (the search says %.3f); %.3f of the region "
                    "without the "
                    "radius arrives\n",
                    angle, share, region.litFraction, all.litFraction);
    }
}

// A ghost's lit pupil can change shape with the wavelength, not only shift: the double Gauss 50 mm's
// R3->R1 at 22.28-22.40 deg passes a crescent and, 8 mm below it, a patch about 5 x 3 mm at 650 nm
// (12 % of the ghost's flux at 22.28 deg) that is gone at the d line. A region searched at 650 nm holds
// every point of a 768 x 768 pass whose 650 nm ray arrives within the counting radius; the region
// searched at the d line, which the ghost table once used for every wavelength, holds none of the patch.
TEST(PupilRegion, SearchedAtItsOwnWavelengthHoldsLightThatOthersLack) {
    const LensBench s("double-gauss-50mm-f2.lens");
    const LensAtWavelength red(s.lens, 650.0, s.sensorZ), d(s.lens, lines::d, s.sensorZ);
    const std::vector<PathStep> steps = stepsOf(s.lens, "R3\u2192R1");
    ASSERT_FALSE(steps.empty());
    for (double angle : {22.28, 22.33, 22.38}) {
        const Field field{degToRad(angle), 0.0};
        const PupilRegion own = pupilRegion(s.pupil, field, Sampling::Reaim, red, steps, test::kMaxRadius);
        const PupilRegion atD = pupilRegion(s.pupil, field, Sampling::Reaim, d, steps, test::kMaxRadius);
        const Coverage c = coverage(s, red, steps, field, {own, atD}, test::kMaxRadius);
        EXPECT_EQ(c.outside[0], 0) << angle << " deg: " << c.outside[0] << " of " << c.lit
                                   << " points lit at 650 nm outside its region";
        EXPECT_GT(c.outside[1], c.lit / 50) << angle << " deg: the d line's region should miss the 650 nm patch";
        std::printf("%.2f deg: %d points lit at 650 nm; outside the 650 nm region %d, outside the d line's %d\n", angle,
                    c.lit, c.outside[0], c.outside[1]);
    }
}

// The traced renderer and the ghost report trace every wavelength on one region per path, the square
// over the regions found at the shortest and longest of them. On the same ghost and angles, that of
// 450 and 650 nm holds every point lit at 450, 550 and 650 nm.
TEST(PupilRegion, BandRegionHoldsTheLightOfEveryWavelengthInTheBand) {
    const LensBench s("double-gauss-50mm-f2.lens");
    const LensAtWavelength ends[] = {LensAtWavelength(s.lens, 450.0, s.sensorZ),
                                     LensAtWavelength(s.lens, 650.0, s.sensorZ)};
    const std::vector<PathStep> steps = stepsOf(s.lens, "R3\u2192R1");
    ASSERT_FALSE(steps.empty());
    for (double angle : {22.28, 22.33, 22.38}) {
        const Field field{degToRad(angle), 0.0};
        const PupilRegion band = bandRegion(s.pupil, field, Sampling::Reaim, ends, steps);
        for (const LensAtWavelength* L : {&ends[0], &s.L, &ends[1]}) {
            const Coverage c = coverage(s, *L, steps, field, {band});
            ASSERT_GT(c.lit, 0);
            EXPECT_EQ(c.outside[0], 0) << angle << " deg, " << L->lambdaNm << " nm: " << c.outside[0] << " of " << c.lit
                                       << " lit points outside";
        }
    }
}

namespace {

// Where rays through (x, 0) of the pupil plane start arriving or stop, scanning x across [-half, half]
// (0.1 um apart at the widest region here).
std::vector<double> edgesAlongX(const LensBench& s, const std::vector<PathStep>& steps, const Field& field,
                                double half) {
    const std::vector<RayResult> hits = scanLine(s, steps, field, half, true);
    const double step = 2.0 * half / kScanPoints;
    std::vector<double> edges;
    for (int i = 1; i < kScanPoints; ++i)
        if ((hits[i].status == optics::RayStatus::Ok) != (hits[i - 1].status == optics::RayStatus::Ok))
            edges.push_back(-half + i * step);
    return edges;
}

} // namespace

// On the axis every lit shape is a disc or rings about it, and its edges along one diameter give the
// shares of its area exactly. The wide angle's R4->R2 passes a disc of radius r0 and a ring from r1
// to r2 narrower (0.26 mm) than the region search's spacing there (0.38 mm): the ring's points are
// one point thick across it, except on diagonal stretches, where its staircase may link a point to
// neighbours along both x and y; the disc is thick everywhere but at its rim's extremes (a row or
// column of one point). So the thin share lies between the ring's share of the area and a good part
// of it, while a disc's is near zero: the ghost table's threshold (0.05) lies between the two.
TEST(PupilRegion, ThinShareIsTheShareOfLightNarrowerThanItsPoints) {
    const LensBench wide("wide-angle-16.7mm-f4.lens");
    const Field axis{0.0, 0.0};
    const PupilRegion disc = pupilRegion(wide.pupil, axis, Sampling::Reaim, wide.L, pathSteps(wide.lens, std::nullopt));
    EXPECT_LT(disc.thinShare, 0.01);
    const std::vector<PathStep> ring = stepsOf(wide.lens, "R4\u2192R2");
    const PupilRegion region = pupilRegion(wide.pupil, axis, Sampling::Reaim, wide.L, ring);
    const std::vector<double> e = edgesAlongX(wide, ring, axis, region.half);
    ASSERT_EQ(e.size(), 6u);
    const double r0 = 0.5 * (e[3] - e[2]), r1 = 0.5 * (e[4] - e[1]), r2 = 0.5 * (e[5] - e[0]);
    const double ringShare = (r2 * r2 - r1 * r1) / (r0 * r0 + r2 * r2 - r1 * r1);
    std::printf(
        "R4->R2 on the axis: disc %.3f mm, ring %.3f-%.3f mm: ring's share %.3f, thin share %.3f; direct image %.4f\n",
        r0, r1, r2, ringShare, region.thinShare, disc.thinShare);
    EXPECT_LT(region.thinShare, ringShare + 0.01);
    EXPECT_GT(region.thinShare, 0.5 * ringShare);
}
