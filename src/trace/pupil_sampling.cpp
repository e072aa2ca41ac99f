#include "trace/pupil_sampling.h"

#include "trace/region_search.h"

#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>

namespace ff::trace {

using detail::Found;
using detail::RegionSearch;
using detail::withPoints;

PupilRegion pupilRegion(const PupilFrame& frame, const Field& field, Sampling sampling, const LensAtWavelength& L,
                        const std::vector<PathStep>& steps, double maxRadiusMm) {
    if (sampling == Sampling::ParaxialGrid) return {0.0, 0.0, frame.radius, true};
    const RegionSearch search(frame, field, L, steps, maxRadiusMm);
    const Found found = findPieces(search);
    if (found.all.empty()) return {0.0, 0.0, frame.radius, true}; // nothing gets through: the paraxial pupil
    return withPoints(search.region(found.all), found.points);
}

PupilRegion bandRegion(const PupilFrame& frame, const Field& field, Sampling sampling,
                       std::span<const LensAtWavelength> ends, const std::vector<PathStep>& steps, double maxRadiusMm) {
    double xMin = 1e300, xMax = -1e300, yMin = 1e300, yMax = -1e300, litArea = 0.0, thin = 0.0;
    std::vector<glm::dvec2> lit;
    for (std::size_t e = 0; e < ends.size(); ++e) {
        if (e > 0 && ends[e].lambdaNm == ends[0].lambdaNm) continue; // a band of one wavelength: one search
        const PupilRegion r = pupilRegion(frame, field, sampling, ends[e], steps, maxRadiusMm);
        if (r.discOnly) continue; // paraxial sampling, or no light found at this wavelength
        xMin = std::min(xMin, r.cx - r.half), xMax = std::max(xMax, r.cx + r.half);
        yMin = std::min(yMin, r.cy - r.half), yMax = std::max(yMax, r.cy + r.half);
        litArea = std::max(litArea, r.litFraction * 4.0 * r.half * r.half);
        thin = std::max(thin, r.thinShare);
        lit.insert(lit.end(), r.litPoints.begin(), r.litPoints.end());
    }
    if (xMin > xMax) return {0.0, 0.0, frame.radius, true};
    const double half = 0.5 * std::max(xMax - xMin, yMax - yMin);
    return {0.5 * (xMin + xMax), 0.5 * (yMin + yMax), half, false, std::min(1.0, litArea / (4.0 * half * half)), thin,
            std::move(lit)};
}

} // namespace ff::trace
