// Edge-resolved bundle moments against a brute-force reference: the same ghost's light measured on a
// 512 x 512 pupil grid (each vignetting edge then moves the moments by steps of 1/512 of a cell row).

#include "core/units.h"
#include "trace/ghost_path.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lens_bench.h"

using namespace ff;
using namespace ff::trace;
using test::kMaxRadius;
using test::LensBench;

namespace {

// The largest of the centroid error (relative to the spread) and the spreads' relative errors.
double momentError(const BundleMoments& m, const BundleMoments& ref) {
    const double sx = std::sqrt(ref.mxx), sy = std::sqrt(ref.myy), s = std::max(sx, sy);
    return std::max({std::abs(m.centroidX - ref.centroidX) / s, std::abs(m.centroidY - ref.centroidY) / s,
                     std::abs(std::sqrt(m.mxx) - sx) / sx, std::abs(std::sqrt(m.myy) - sy) / sy});
}

} // namespace

TEST(BundleMoments, ResolvedEdgesMatchAFineGrid) {
    const LensBench s("cooke-triplet-50mm-f5.lens");
    const Field field{degToRad(14.0), 0.0};
    int checked = 0;
    double worstResolved = 0.0, worstPlain = 0.0;
    for (const GhostPair& g : enumerateGhosts(s.lens)) {
        const auto steps = pathSteps(s.lens, g);
        const PupilRegion region = pupilRegion(s.pupil, field, Sampling::Reaim, s.L, steps);
        const BundleMoments ref = s.grid(steps, field, region, 512, 0);
        // Vignetted ghosts only: between 20 % and 90 % of the region's rays arrive.
        const double arriving = double(ref.surviving) / double(ref.launched);
        if (ref.energy <= 0.0 || arriving < 0.2 || arriving > 0.9) continue;
        ++checked;
        for (int n : {29, 32, 37}) {
            const double plain = momentError(s.grid(steps, field, region, n, 0), ref);
            // 4 x 4 sub-grids, as the ghost table uses.
            const double resolved = momentError(s.grid(steps, field, region, n, 4), ref);
            worstPlain = std::max(worstPlain, plain);
            worstResolved = std::max(worstResolved, resolved);
            // Interior cells still carry their quadrature error, and the reference its rows' steps
            // (0.14 % at worst with each sub-cell's lit share on 4 x 4; 0.49 % counting whole
            // sub-cells of 8 x 8; 2.1 % with the edges unresolved).
            EXPECT_LT(resolved, 1e-2) << g.label() << " grid " << n << " (unresolved: " << plain << ")";
        }
    }
    ASSERT_GE(checked, 3);
    std::printf(
        "%d vignetted ghosts at 14 deg, grids 29/32/37: worst moment error %.2e resolved, %.2e on the plain grid\n",
        checked, worstResolved, worstPlain);
    EXPECT_LT(worstResolved, 0.25 * worstPlain);
}

// A ghost that lands across the counting radius: on the telephoto at 9.88-9.92 deg, R7->R5 lands
// 41-68 mm from the axis and only its inner edge counts, a sliver whose tips, far out along x, carry
// much of its tangential spread. Over a region holding all of the ghost's light the sliver is a cell
// or two of a 32 grid thick, and all five rays of a cell at a tip can land beyond the radius while
// part of the cell lands within it: before such cells were resolved that grid's tangential spread
// fell 8 % between 9.900 and 9.905 deg (the 1024 grid's 0.7 %) and was 7.2 % off at worst, now 2.6 %.
// Over the region of the light landing within the radius (what the ghost table uses) the sliver
// spans more of the square, and 32 and 64 grids follow it to 0.4 % and 0.2 %.
TEST(BundleMoments, ResolvedSliverAtTheCountingRadiusMatchesAFineGrid) {
    const LensBench s("telephoto-127mm-f5.6.lens");
    std::vector<PathStep> steps;
    for (const GhostPair& g : enumerateGhosts(s.lens))
        if (g.label() == "R7\u2192R5") steps = pathSteps(s.lens, g);
    ASSERT_FALSE(steps.empty());
    double worstAll = 0.0, worst32 = 0.0, worst64 = 0.0;
    for (double angle : {9.88, 9.89, 9.9, 9.905, 9.91, 9.92}) {
        const Field field{degToRad(angle), 0.0};
        const PupilRegion all = pupilRegion(s.pupil, field, Sampling::Reaim, s.L, steps);
        const PupilRegion counted = pupilRegion(s.pupil, field, Sampling::Reaim, s.L, steps, test::kMaxRadius);
        const BundleMoments ref = s.grid(steps, field, all, 1024, 0);
        ASSERT_GT(ref.energy, 0.0);
        const auto error = [&](const BundleMoments& m) {
            return std::max(momentError(m, ref), std::abs(m.energy - ref.energy) / ref.energy);
        };
        const BundleMoments mAll = s.grid(steps, field, all, 32, 8), m32 = s.grid(steps, field, counted, 32, 8),
                            m64 = s.grid(steps, field, counted, 64, 8);
        worstAll = std::max(worstAll, error(mAll));
        worst32 = std::max(worst32, error(m32));
        worst64 = std::max(worst64, error(m64));
        std::printf("%.3f deg: sigma x %.3f mm (1024); 32 over all the light %.3f, error %.2e; over the counted light "
                    "32 %.3f, %.2e; "
                    "64 %.3f, %.2e\n",
                    angle, std::sqrt(ref.mxx), std::sqrt(mAll.mxx), error(mAll), std::sqrt(m32.mxx), error(m32),
                    std::sqrt(m64.mxx), error(m64));
    }
    EXPECT_LT(worstAll, 0.035);
    EXPECT_LT(worst32, 0.01);
    EXPECT_LT(worst64, 0.005);
}

// Moments of disjoint parts of a bundle, combined, are those of the whole measured at once: the Cooke
// triplet's R6->R4 at 14 deg and azimuth 30 deg (so that the mixed moment is not zero), its 64 x 64
// grid cut into three bands of rows measured apart.
TEST(BundleMoments, PartsCombineIntoTheWhole) {
    const LensBench s("cooke-triplet-50mm-f5.lens");
    const Field field{degToRad(14.0), degToRad(30.0)};
    const auto ghosts = enumerateGhosts(s.lens);
    ASSERT_FALSE(ghosts.empty());
    const auto steps = pathSteps(s.lens, ghosts.back());
    const Bundle b = regionBundle(s.pupil, field, pupilRegion(s.pupil, field, Sampling::Reaim, s.L, steps), 64);
    std::vector<RayResult> hits(b.rays.size());
    s.tracer.trace(s.L, steps, b.rays, hits);
    const BundleMoments whole = measureBundle(b, hits, 2.0, kMaxRadius);
    ASSERT_GT(whole.energy, 0.0);
    ASSERT_GT(std::abs(whole.mxy), 1e-3 * std::sqrt(whole.mxx * whole.myy));
    std::vector<BundleMoments> parts;
    for (const auto& [first, last] : {std::pair{0, 20}, std::pair{20, 45}, std::pair{45, 64}}) {
        std::vector<double> areas(hits.size(), 0.0);
        for (int j = first; j < last; ++j)
            for (int i = 0; i < b.n; ++i) areas[static_cast<std::size_t>(j) * b.n + i] = b.cellArea;
        parts.push_back(measureSamples(hits, areas, 2.0, kMaxRadius));
    }
    const BundleMoments m = combineMoments(parts);
    EXPECT_EQ(m.launched, whole.launched);
    EXPECT_EQ(m.surviving, whole.surviving);
    EXPECT_EQ(m.blocked, whole.blocked);
    EXPECT_NEAR(m.energy, whole.energy, 1e-12 * whole.energy);
    const double scale = std::sqrt(whole.mxx + whole.myy);
    EXPECT_NEAR(m.centroidX, whole.centroidX, 1e-12 * scale);
    EXPECT_NEAR(m.centroidY, whole.centroidY, 1e-12 * std::max(scale, std::abs(whole.centroidY)));
    EXPECT_NEAR(m.mxx, whole.mxx, 1e-10 * scale * scale);
    EXPECT_NEAR(m.myy, whole.myy, 1e-10 * scale * scale);
    EXPECT_NEAR(m.mxy, whole.mxy, 1e-10 * scale * scale);
}
