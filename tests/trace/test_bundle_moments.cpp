// Edge-resolved bundle moments against a brute-force reference: the same ghost's light measured on a
// 512 x 512 pupil grid (each vignetting edge then moves the moments by steps of 1/512 of a cell row).

#include "core/units.h"
#include "lens_bench.h"
#include "trace/ghost_path.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace ff;
using namespace ff::trace;
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
            // 8 x 8 sub-grids, as the ghost table uses.
            const double resolved = momentError(s.grid(steps, field, region, n, 8), ref);
            worstPlain = std::max(worstPlain, plain);
            worstResolved = std::max(worstResolved, resolved);
            // Interior cells still carry their quadrature error (0.49 % at worst when this was written,
            // against 2.0 % with the edges unresolved).
            EXPECT_LT(resolved, 1e-2) << g.label() << " grid " << n << " (unresolved: " << plain << ")";
        }
    }
    ASSERT_GE(checked, 3);
    std::printf("%d vignetted ghosts at 14 deg, grids 29/32/37: worst moment error %.2e resolved, %.2e on the plain grid\n", checked,
                worstResolved, worstPlain);
    EXPECT_LT(worstResolved, 0.25 * worstPlain);
}

// A ghost that lands across the counting radius: on the telephoto at 9.88-9.92 deg, R7->R5 lands
// 41-68 mm from the axis and only its inner edge counts, a sliver a cell or two of a 32 grid thick
// whose tips, far out along x, carry much of its tangential spread. All five rays of a cell at a tip
// can land beyond the radius while part of the cell lands within it; before such cells were resolved
// the 32 grid's tangential spread dropped 8 % between 9.900 and 9.905 deg.
TEST(BundleMoments, ResolvedSliverAtTheCountingRadiusMatchesAFineGrid) {
    const LensBench s("telephoto-127mm-f5.6.lens");
    std::vector<PathStep> steps;
    for (const GhostPair& g : enumerateGhosts(s.lens))
        if (g.label() == "R7\u2192R5") steps = pathSteps(s.lens, g);
    ASSERT_FALSE(steps.empty());
    double worst = 0.0;
    for (int a = 0; a <= 8; ++a) {
        const Field field{degToRad(9.88 + 0.005 * a), 0.0};
        const PupilRegion region = pupilRegion(s.pupil, field, Sampling::Reaim, s.L, steps);
        const BundleMoments ref = s.grid(steps, field, region, 1024, 0);
        const BundleMoments m = s.grid(steps, field, region, 32, 8);
        ASSERT_GT(ref.energy, 0.0);
        const double e = std::max(momentError(m, ref), std::abs(m.energy - ref.energy) / ref.energy);
        worst = std::max(worst, e);
        std::printf("%.3f deg: flux %.3e vs %.3e, sigma x %.3f vs %.3f mm, error %.2e\n", 9.88 + 0.005 * a, m.energy, ref.energy,
                    std::sqrt(m.mxx), std::sqrt(ref.mxx), e);
    }
    EXPECT_LT(worst, 0.03);
}
