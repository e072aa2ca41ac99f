#pragma once
// Analytic passes over a lens's pupil plane that the pupil-region and pupil-parts tests check the
// search against: a 768 x 768 pass over everything that could enter the front surface, and fine scans
// along one line of the pupil.

#include "trace/ghost_path.h"

#include <cmath>
#include <initializer_list>
#include <string>
#include <vector>

#include "lens_bench.h"

namespace ff::test {

// Points of a 768 x 768 analytic pass over the whole square the region search starts from (everything
// that could enter the front surface) whose rays arrive at L's wavelength, within maxRadius of the axis
// when it is > 0: how many, and how many of them lie outside each of the given regions.
struct Coverage {
    int lit = 0;
    std::vector<int> outside;
};

inline Coverage coverage(const LensBench& s, const trace::LensAtWavelength& L,
                         const std::vector<trace::PathStep>& steps, const trace::Field& field,
                         std::initializer_list<trace::PupilRegion> regions, double maxRadius = 0.0) {
    const trace::Bundle b =
        trace::gridBundle(s.pupil, field, 768, 0.0, 0.0, trace::searchHalfSize(s.pupil, field), false);
    std::vector<trace::RayResult> hits(b.rays.size());
    trace::traceAnalytic(L, steps, b.rays, hits);
    Coverage c;
    c.outside.assign(regions.size(), 0);
    for (int j = 0; j < b.n; ++j)
        for (int i = 0; i < b.n; ++i) {
            const trace::RayResult& r = hits[static_cast<std::size_t>(j) * b.n + i];
            if (r.status != optics::RayStatus::Ok ||
                (maxRadius > 0.0 && std::hypot(r.sensorPoint.x, r.sensorPoint.y) > maxRadius))
                continue;
            const double x = b.x0 + (i + 0.5) * b.cell, y = b.y0 + (j + 0.5) * b.cell;
            ++c.lit;
            std::size_t k = 0;
            for (const trace::PupilRegion& region : regions)
                c.outside[k++] += std::abs(x - region.cx) > region.half || std::abs(y - region.cy) > region.half;
        }
    return c;
}

/// The steps of the ghost with this label (empty when the lens has none).
inline std::vector<trace::PathStep> stepsOf(const optics::Lens& lens, const std::string& label) {
    for (const trace::GhostPair& g : trace::enumerateGhosts(lens))
        if (g.label() == label) return trace::pathSteps(lens, g);
    return {};
}

constexpr int kScanPoints = 200000;

// The hits of kScanPoints parallel rays through the line y = 0 (alongX) or x = 0 of the pupil plane,
// spread evenly across [-half, half]: point i at -half + (i + 0.5) x 2 half / kScanPoints; at the bench's
// wavelength, or at `at`'s.
inline std::vector<trace::RayResult> scanLine(const LensBench& s, const std::vector<trace::PathStep>& steps,
                                              const trace::Field& field, double half, bool alongX,
                                              const trace::LensAtWavelength* at = nullptr) {
    const optics::Ray centre = trace::gridBundle(s.pupil, field, 1, 0.0, 0.0, half, false).rays[0]; // through (0, 0)
    const double step = 2.0 * half / kScanPoints;
    std::vector<optics::Ray> line(kScanPoints, centre);
    for (int i = 0; i < kScanPoints; ++i)
        (alongX ? line[i].origin.x : line[i].origin.y) += -half + (i + 0.5) * step; // parallel rays
    std::vector<trace::RayResult> hits(kScanPoints);
    trace::traceAnalytic(at ? *at : s.L, steps, line, hits);
    return hits;
}

} // namespace ff::test
