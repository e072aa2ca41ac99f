// How the pupil-region search cuts a path's light into parts, each against an analytic pass or scan
// of its own: pieces far apart get squares of their own that hold all of their light, the searches at
// several wavelengths help one another, the parts keep the light's mirror symmetry, and a search
// looks where a neighbouring field angle found light.

#include "core/units.h"
#include "trace/ghost_path.h"
#include "trace/pupil_search.h"

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

namespace {

// The stretches of the line x = 0 of the pupil plane whose rays arrive within the counting radius,
// found by a scan across [-half, half] (under half a micron apart here): (start, end). At the bench's
// wavelength, or at `at`'s.
std::vector<std::pair<double, double>> litAlongY(const LensBench& s, const std::vector<PathStep>& steps,
                                                 const Field& field, double half,
                                                 const LensAtWavelength* at = nullptr) {
    const std::vector<RayResult> hits = scanLine(s, steps, field, half, false, at);
    const double step = 2.0 * half / kScanPoints;
    std::vector<std::pair<double, double>> lit;
    for (int i = 0; i < kScanPoints; ++i) {
        const bool on = hits[i].status == optics::RayStatus::Ok &&
                        std::hypot(hits[i].sensorPoint.x, hits[i].sensorPoint.y) <= test::kMaxRadius;
        const double y = -half + (i + 0.5) * step;
        if (!on) continue;
        if (!lit.empty() && lit.back().second >= y - 1.5 * step)
            lit.back().second = y;
        else
            lit.push_back({y, y});
    }
    return lit;
}

// Whether the stretch [start, end] of the line x = 0 lies within one of the parts.
bool holdsStretch(const std::vector<PupilRegion>& parts, double start, double end) {
    return std::any_of(parts.begin(), parts.end(), [&](const PupilRegion& p) {
        return std::abs(p.cx) <= p.half && start >= p.cy - p.half && end <= p.cy + p.half;
    });
}

// The ghost table's wavelengths: 650, 550 and 450 nm.
std::vector<LensAtWavelength> tableWavelengths(const LensBench& s) {
    std::vector<LensAtWavelength> Ls;
    for (double lambda : {650.0, 550.0, 450.0}) Ls.emplace_back(s.lens, lambda, s.sensorZ);
    return Ls;
}

} // namespace

// The wide angle's R4->R2 at 31.70-31.80 deg (550 nm, counting radius) passes a disc about 1.8 mm
// across and, 18 mm above it in the pupil, a band under 0.1 mm thick and a few millimetres long along
// x, found here by a fine scan up the line x = 0. A regular coarse pass steps over the band at some of
// these angles (it did at 31.72-31.78 deg); the jittered one finds it at each, and pupilParts gives
// the disc and the band squares of their own (so each gets a grid at its own scale): disjoint, and
// holding every lit stretch of the scan.
TEST(PupilRegion, PartsHoldLightFallingInPiecesFarApart) {
    const LensBench s("wide-angle-16.7mm-f4.lens");
    const std::vector<PathStep> steps = stepsOf(s.lens, "R4\u2192R2");
    ASSERT_FALSE(steps.empty());
    for (double angle : {31.70, 31.72, 31.74, 31.76, 31.78, 31.80}) {
        const Field field{degToRad(angle), 0.0};
        const auto lit = litAlongY(s, steps, field, searchHalfSize(s.pupil, field));
        ASSERT_GE(lit.size(), 2u) << angle << " deg";
        const auto [bandStart, bandEnd] = lit.back();
        EXPECT_LT(bandEnd - bandStart, 0.1) << angle << " deg: the band";
        EXPECT_GT(bandStart - lit.front().second, 15.0) << angle << " deg: the band lies far from the disc";
        const std::vector<PupilRegion> parts =
            pupilParts(s.pupil, field, Sampling::Reaim, s.L, steps, test::kMaxRadius);
        ASSERT_EQ(parts.size(), 2u) << angle << " deg";
        const PupilRegion& a = parts[0];
        const PupilRegion& b = parts[1];
        EXPECT_TRUE(std::abs(a.cx - b.cx) >= a.half + b.half || std::abs(a.cy - b.cy) >= a.half + b.half)
            << angle << " deg: parts overlap";
        for (const auto& [start, end] : lit) {
            EXPECT_TRUE(holdsStretch(parts, start, end))
                << angle << " deg: light at y " << start << " to " << end << " mm outside the parts";
        }
        std::printf("%.2f deg: disc %.3f..%.3f mm, band %.4f..%.4f mm; parts' half sides %.2f and %.2f mm\n", angle,
                    lit.front().first, lit.front().second, bandStart, bandEnd, a.half, b.half);
    }
}

// The same ghost at 30.90-30.98 deg and 450 nm passes a band 0.055 mm thick, 17 mm above its disc in
// the pupil (found by the fine scan up x = 0). Searched with 550 and 650 nm, each search with coarse
// points of its own, 0.28 mm apart, the 450 nm search's points step over the band at each of these
// angles, and the 650 nm search's meet it; the 450 nm search looks again where the others found
// light, and its parts hold the band.
TEST(PupilRegion, SearchesAtSeveralWavelengthsFindWhatOneSteppedOver) {
    const LensBench s("wide-angle-16.7mm-f4.lens");
    const std::vector<PathStep> steps = stepsOf(s.lens, "R4\u2192R2");
    ASSERT_FALSE(steps.empty());
    const std::vector<LensAtWavelength> Ls = tableWavelengths(s);
    for (double angle : {30.90, 30.94, 30.98}) {
        const Field field{degToRad(angle), 0.0};
        const auto lit = litAlongY(s, steps, field, searchHalfSize(s.pupil, field), &Ls[2]);
        ASSERT_EQ(lit.size(), 2u) << angle << " deg";
        EXPECT_LT(lit.back().second - lit.back().first, 0.1) << angle << " deg: the band";
        const auto parts = pupilPartsByWavelength(s.pupil, field, Sampling::Reaim, Ls, steps, test::kMaxRadius);
        ASSERT_EQ(parts.size(), 3u);
        for (const auto& [start, end] : lit) {
            EXPECT_TRUE(holdsStretch(parts[2], start, end))
                << angle << " deg: 450 nm light at y " << start << " to " << end << " mm outside its parts";
        }
    }
}

// The double Gauss 50 mm's R11->R5 near the edge of its field (650 nm, counting radius) passes two
// patches at x = +-8 mm and, below them on x = 0, a band 0.09 mm thick at 24.646-24.650 deg, which
// the coarse pass (0.73 mm apart) and the regular local passes over all the light (0.3 mm apart)
// step over: cut into parts for the patches alone, the region lost the band (8 % of the ghost's
// flux; its sigma_r halved within 0.001 deg). Whatever the region is cut into holds every lit stretch
// of a fine scan up x = 0.
TEST(PupilRegion, PartsHoldTheLightBetweenThem) {
    const LensBench s("double-gauss-50mm-f2.lens");
    const std::vector<PathStep> steps = stepsOf(s.lens, "R11\u2192R5");
    ASSERT_FALSE(steps.empty());
    const std::vector<LensAtWavelength> Ls = tableWavelengths(s);
    for (double angle : {24.646, 24.648, 24.650}) {
        const Field field{degToRad(angle), 0.0};
        const auto lit = litAlongY(s, steps, field, searchHalfSize(s.pupil, field), &Ls[0]);
        ASSERT_FALSE(lit.empty()) << angle << " deg";
        const auto byWavelength = pupilPartsByWavelength(s.pupil, field, Sampling::Reaim, Ls, steps, test::kMaxRadius);
        for (const auto& parts :
             {pupilParts(s.pupil, field, Sampling::Reaim, Ls[0], steps, test::kMaxRadius), byWavelength[0]})
            for (const auto& [start, end] : lit) {
                EXPECT_TRUE(holdsStretch(parts, start, end)) << angle << " deg: light at y " << start << " to " << end
                                                             << " mm outside the " << parts.size() << " part(s)";
            }
    }
}

// The double Gauss 50 mm's R3->R1 at 21.8406-21.8407 deg and 450 nm (counting radius) passes, on the
// line x = 0, a crescent's stretch and, more than 5 mm below it, a patch's stretch under 0.5 mm long;
// the search finds the two far apart. A square over the crescent (20 mm across) centred on it would
// reach over the patch's; slid along the gap, each piece gets a square of its own: two parts,
// disjoint, the patch's a few millimetres across, holding every lit stretch of the scan.
TEST(PupilRegion, PartsSlideApartWhereASquareWouldReachOverTheOtherPiece) {
    const LensBench s("double-gauss-50mm-f2.lens");
    const std::vector<PathStep> steps = stepsOf(s.lens, "R3\u2192R1");
    ASSERT_FALSE(steps.empty());
    const std::vector<LensAtWavelength> Ls = tableWavelengths(s);
    for (double angle : {21.8406, 21.8407}) {
        const Field field{degToRad(angle), 0.0};
        const auto lit = litAlongY(s, steps, field, searchHalfSize(s.pupil, field), &Ls[2]);
        ASSERT_EQ(lit.size(), 2u) << angle << " deg";
        const auto [patchStart, patchEnd] = lit.front();
        EXPECT_LT(patchEnd - patchStart, 0.5) << angle << " deg: the patch";
        EXPECT_GT(lit.back().first - patchEnd, 5.0) << angle << " deg: the patch lies far from the crescent";
        const auto parts = pupilPartsByWavelength(s.pupil, field, Sampling::Reaim, Ls, steps, test::kMaxRadius)[2];
        ASSERT_EQ(parts.size(), 2u) << angle << " deg";
        const PupilRegion& a = parts[0];
        const PupilRegion& b = parts[1];
        EXPECT_TRUE(std::abs(a.cx - b.cx) >= a.half + b.half || std::abs(a.cy - b.cy) >= a.half + b.half)
            << angle << " deg: parts overlap";
        EXPECT_LT(std::min(a.half, b.half), 2.0) << angle << " deg: the patch's square";
        for (const auto& [start, end] : lit) {
            EXPECT_TRUE(holdsStretch(parts, start, end))
                << angle << " deg: light at y " << start << " to " << end << " mm outside the parts";
        }
    }
}

// The lit points a part carries (the region search's last local pass over it, for the grid to resolve
// the light between its rays) lie in the part's square, and each one's ray, traced again here, arrives
// within the counting radius: the double Gauss 50 mm's R3->R1 at 21.8406 deg (a crescent and a patch,
// two parts) and the zoom's R9->R3 at 13.1515 deg (a disc and two slivers far from it, one part), at
// 450 nm.
TEST(PupilRegion, PartsCarryLitPointsOfTheirOwnSquare) {
    for (const auto& [lens, label, angle] : {std::tuple{"double-gauss-50mm-f2.lens", "R3\u2192R1", 21.8406},
                                             std::tuple{"zoom-70-200mm-f2.8.lens", "R9\u2192R3", 13.1515}}) {
        const LensBench s(lens);
        const std::vector<PathStep> steps = stepsOf(s.lens, label);
        ASSERT_FALSE(steps.empty()) << lens;
        const std::vector<LensAtWavelength> Ls = tableWavelengths(s);
        const Field field{degToRad(angle), 0.0};
        const auto parts = pupilPartsByWavelength(s.pupil, field, Sampling::Reaim, Ls, steps, test::kMaxRadius);
        for (const PupilRegion& part : parts[2]) {
            ASSERT_GT(part.litPoints.size(), 10u) << lens << ": the part at (" << part.cx << ", " << part.cy << ")";
            std::vector<optics::Ray> rays;
            for (const glm::dvec2& p : part.litPoints) {
                EXPECT_LE(std::max(std::abs(p.x - part.cx), std::abs(p.y - part.cy)), part.half)
                    << lens << ": (" << p.x << ", " << p.y << ")";
                rays.push_back(gridBundle(s.pupil, field, 1, p.x, p.y, 0.0, false).rays.front());
            }
            std::vector<RayResult> hits(rays.size());
            traceAnalytic(Ls[2], steps, rays, hits, Weighting::None);
            for (std::size_t k = 0; k < hits.size(); ++k) {
                const bool arrives = hits[k].status == optics::RayStatus::Ok &&
                                     std::hypot(hits[k].sensorPoint.x, hits[k].sensorPoint.y) <= test::kMaxRadius;
                EXPECT_TRUE(arrives) << lens << ": the lit point (" << part.litPoints[k].x << ", "
                                     << part.litPoints[k].y << ")";
            }
        }
    }
}

namespace {

// Whether every part has a mirror image across x = 0 among the parts (within 5 % of their summed
// half sides).
void expectMirrored(const std::vector<PupilRegion>& parts, double angle) {
    const double width =
        std::accumulate(parts.begin(), parts.end(), 0.0, [](double w, const PupilRegion& p) { return w + p.half; });
    for (const PupilRegion& p : parts) {
        const bool mirrored = std::any_of(parts.begin(), parts.end(), [&](const PupilRegion& q) {
            return std::abs(q.cx + p.cx) < 0.05 * width && std::abs(q.cy - p.cy) < 0.05 * width &&
                   std::abs(q.half - p.half) < 0.05 * width;
        });
        EXPECT_TRUE(mirrored) << angle << " deg: the part at x " << p.cx << " mm has no mirror image";
    }
}

// The points of an analytic pass whose rays arrive at L's wavelength within the counting radius: how
// many, how many of them lie outside every part, and their extent along x.
struct PassOverParts {
    int lit = 0, outside = 0;
    double xMin = 1e300, xMax = -1e300;
};

PassOverParts passOverParts(const Bundle& b, const LensAtWavelength& L, const std::vector<PathStep>& steps,
                            const std::vector<PupilRegion>& parts) {
    std::vector<RayResult> hits(b.rays.size());
    traceAnalytic(L, steps, b.rays, hits);
    PassOverParts out;
    for (std::size_t k = 0; k < hits.size(); ++k) {
        const RayResult& r = hits[k];
        if (r.status != optics::RayStatus::Ok || std::hypot(r.sensorPoint.x, r.sensorPoint.y) > test::kMaxRadius)
            continue;
        const double x = b.x0 + (static_cast<double>(k % b.n) + 0.5) * b.cell,
                     y = b.y0 + (static_cast<double>(k / b.n) + 0.5) * b.cell;
        ++out.lit;
        out.xMin = std::min(out.xMin, x), out.xMax = std::max(out.xMax, x);
        out.outside += std::none_of(parts.begin(), parts.end(), [&](const PupilRegion& p) {
            return std::abs(x - p.cx) <= p.half && std::abs(y - p.cy) <= p.half;
        });
    }
    return out;
}

} // namespace

// A rotationally symmetric lens passes light from a source at azimuth 0 through a pupil region that is
// its own mirror image across x = 0. The double Gauss 50 mm's R11->R5 at the edge of its field
// (24.681-24.690 deg, 650 nm, counting radius) passes two patches about 1.7 mm across at x = +-8.1 mm:
// the search's jittered coarse pass meets only one of them at these angles, completes what it found
// by symmetry (without that, the ghost's tangential spread halved), and the region, or its parts,
// mirror onto themselves.
TEST(PupilRegion, KeepsTheMirrorSymmetryOfTheLight) {
    const LensBench s("double-gauss-50mm-f2.lens");
    const LensAtWavelength red(s.lens, 650.0, s.sensorZ);
    const std::vector<PathStep> steps = stepsOf(s.lens, "R11\u2192R5");
    ASSERT_FALSE(steps.empty());
    for (double angle = 24.681; angle <= 24.6905; angle += 0.003) {
        const Field field{degToRad(angle), 0.0};
        expectMirrored(pupilParts(s.pupil, field, Sampling::Reaim, red, steps, test::kMaxRadius), angle);
        const Coverage c =
            coverage(s, red, steps, field, {pupilRegion(s.pupil, field, Sampling::Reaim, red, steps, test::kMaxRadius)},
                     test::kMaxRadius);
        EXPECT_EQ(c.outside[0], 0) << angle << " deg";
    }
    // Light that a search finds only where another wavelength's search led it is completed too: R9->R7
    // at 23.8499-23.8529 deg passes two spots 20 mm apart at x = +-10.2 mm, of which the 450 nm search
    // finds one, and only on a look where the 550 or 650 nm search found light (the ghost's tangential
    // spread fell from 17.1 to 0.21 mm while one spot was missing).
    const std::vector<PathStep> spots = stepsOf(s.lens, "R9\u2192R7");
    ASSERT_FALSE(spots.empty());
    const std::vector<LensAtWavelength> Ls = tableWavelengths(s);
    for (double angle : {23.8499, 23.8509, 23.8519, 23.8529}) {
        const Field field{degToRad(angle), 0.0};
        const auto parts = pupilPartsByWavelength(s.pupil, field, Sampling::Reaim, Ls, spots, test::kMaxRadius);
        for (const auto& p : parts) expectMirrored(p, angle);
        // Every point of a 768 x 768 grid whose 450 nm ray arrives lies in a 450 nm part.
        const Bundle b = gridBundle(s.pupil, field, 768, 0.0, 0.0, searchHalfSize(s.pupil, field), false);
        const PassOverParts pass = passOverParts(b, Ls[2], spots, parts[2]);
        EXPECT_GT(pass.lit, 0) << angle << " deg";
        EXPECT_EQ(pass.outside, 0) << angle << " deg: of " << pass.lit << " lit points";
    }
}

// The wide angle's R4->R2 at 550 nm (21.30-21.4175 deg, counting radius) passes, 17.5 mm above the
// rest of its light in the pupil, a band about 6 mm long across x = 0, thinner than the searches'
// local spacing, whose ends send light 4 mm to either side of the ghost's centre. The local passes
// meet the band at some of its points and not others: at 21.4066 and 21.41745 deg the box over those
// stopped short of one end, the part's square held one end and not the other, and the ghost's
// tangential spread fell 1.9 %.
// The band's part mirrors onto itself, and every point of a fine analytic pass over the band whose
// ray arrives lies in a part.
TEST(PupilRegion, PartsHoldBothEndsOfABandAcrossTheMirrorLine) {
    const LensBench s("wide-angle-16.7mm-f4.lens");
    const std::vector<PathStep> steps = stepsOf(s.lens, "R4\u2192R2");
    ASSERT_FALSE(steps.empty());
    const std::vector<LensAtWavelength> Ls = tableWavelengths(s);
    for (double angle : {21.30, 21.36, 21.4066, 21.41745}) {
        const Field field{degToRad(angle), 0.0};
        const auto parts = pupilPartsByWavelength(s.pupil, field, Sampling::Reaim, Ls, steps, test::kMaxRadius);
        expectMirrored(parts[1], angle);
        // 1024 x 1024 points 8 um apart over [-4, 4] x [13.5, 21.5] mm: the band and none of the rest.
        const PassOverParts band =
            passOverParts(gridBundle(s.pupil, field, 1024, 0.0, 17.5, 4.0, false), Ls[1], steps, parts[1]);
        EXPECT_GT(band.lit, 0) << angle << " deg";
        EXPECT_LT(band.xMin, -2.9) << angle << " deg: the band";
        EXPECT_GT(band.xMax, 2.9) << angle << " deg: the band";
        EXPECT_EQ(band.outside, 0) << angle << " deg: of " << band.lit << " lit points of the band";
        std::printf("%.4f deg: band x %.3f..%.3f mm, %d lit points\n", angle, band.xMin, band.xMax, band.lit);
    }
}

namespace {

// The wide angle's R6->R1 at the table's wavelengths, and its searches.
struct WideR6R1 {
    LensBench s{"wide-angle-16.7mm-f4.lens"};
    std::vector<PathStep> steps = stepsOf(s.lens, "R6\u2192R1");
    std::vector<LensAtWavelength> Ls = tableWavelengths(s);

    PupilSearch search(double angleDeg, const PupilHints& hints = {}, bool lookCloser = false) const {
        return searchPupil(s.pupil, Field{degToRad(angleDeg), 0.0}, Sampling::Reaim, Ls, steps, test::kMaxRadius, hints,
                           lookCloser);
    }
};

} // namespace

// The wide angle's R6->R1 at 450 nm passes, 13 mm above the rest of its light in the pupil, a patch
// that shrinks to nothing near 5.5165 deg (found here by the fine scan up x = 0). At 5.5150-5.5160
// deg it is under 0.15 mm across and the searches' coarse points (0.28 mm apart) step over it at
// 450 nm; at 5.512 deg they meet it. Told where the search at 5.512 deg found light, the
// searches at these angles look there and their parts hold the patch; and the looks alone
// (hintsFindLight), at the pieces 5.512 deg found that the search here lacks, tell that searching
// again would find more.
TEST(PupilRegion, LooksWhereANeighbouringAngleFoundLight) {
    const WideR6R1 r;
    const LensBench& s = r.s;
    const std::vector<PathStep>& steps = r.steps;
    ASSERT_FALSE(steps.empty());
    const std::vector<LensAtWavelength>& Ls = r.Ls;
    const PupilSearch neighbour = r.search(5.512);
    for (double angle : {5.5150, 5.5155, 5.5160}) {
        const Field field{degToRad(angle), 0.0};
        const auto lit = litAlongY(s, steps, field, searchHalfSize(s.pupil, field), &Ls[2]);
        ASSERT_GE(lit.size(), 2u) << angle << " deg";
        EXPECT_GT(lit.back().first - lit.front().second, 10.0) << angle << " deg: the patch lies far from the rest";
        EXPECT_LT(lit.back().second - lit.back().first, 0.15) << angle << " deg: the patch";
        const PupilSearch alone = r.search(angle);
        const PupilSearch told = r.search(angle, neighbour.pieces);
        EXPECT_TRUE(told.hintsFoundLight) << angle << " deg";
        for (const auto& [start, end] : lit) {
            EXPECT_TRUE(holdsStretch(told.parts[2], start, end))
                << angle << " deg: 450 nm light at y " << start << " to " << end << " mm outside its parts";
        }
        const PupilHints away = piecesAwayFrom(neighbour, alone);
        const bool missed = !holdsStretch(alone.parts[2], lit.back().first, lit.back().second);
        if (missed) {
            EXPECT_TRUE(hintsFindLight(s.pupil, field, Sampling::Reaim, Ls, steps, test::kMaxRadius, alone, away))
                << angle << " deg";
        }
        std::printf("%.4f deg: patch %.4f..%.4f mm, %s alone\n", angle, lit.back().first, lit.back().second,
                    missed ? "missed" : "found");
    }
}

// Further on the patch shrinks to nothing at 5.5165 deg; at 5.5161-5.5164 deg it is 0.08 to 0.03 mm
// across, smaller than the spacing of the looks at the hints (64 points over the hint's box and two
// coarse cells, 1.1 mm, on every side: 70 um apart), which step over it at some of these angles.
// Told to look closer, as the ghost table's finest step does, the search at each of them finds it
// where the search at 5.5160 deg (told by 5.512 deg's) found it.
TEST(PupilRegion, LooksCloserAtAPieceShrinkingToNothing) {
    const WideR6R1 r;
    ASSERT_FALSE(r.steps.empty());
    const PupilSearch neighbour = r.search(5.5160, r.search(5.512).pieces);
    int plainMissed = 0;
    for (double angle : {5.5161, 5.5162, 5.5163, 5.5164}) {
        const Field field{degToRad(angle), 0.0};
        const auto lit = litAlongY(r.s, r.steps, field, searchHalfSize(r.s.pupil, field), &r.Ls[2]);
        ASSERT_GE(lit.size(), 2u) << angle << " deg";
        const auto [start, end] = lit.back();
        EXPECT_GT(start - lit.front().second, 10.0) << angle << " deg: the patch lies far from the rest";
        EXPECT_LT(end - start, 0.09) << angle << " deg: the patch";
        const PupilSearch closer = r.search(angle, neighbour.pieces, /*lookCloser=*/true);
        EXPECT_TRUE(holdsStretch(closer.parts[2], start, end))
            << angle << " deg: the patch at y " << start << " to " << end << " mm";
        const PupilSearch plain = r.search(angle, neighbour.pieces);
        plainMissed += !holdsStretch(plain.parts[2], start, end);
    }
    std::printf("the looks at the hints alone missed the patch at %d of 4 angles\n", plainMissed);
}
