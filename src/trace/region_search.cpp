#include "trace/region_search.h"

#include <algorithm>
#include <cmath>

namespace ff::trace::detail {

void addPoints(const RegionSearch& search, Found& f, const std::vector<glm::dvec2>& places) {
    f.points.insert(f.points.end(), places.begin(), places.end());
    if (search.symmetric())
        for (const glm::dvec2& p : places) f.points.push_back(search.mirror(p));
}

void completeBySymmetry(const RegionSearch& search, Found& f) {
    if (f.all.empty() || !search.symmetric()) return;
    const std::size_t found = f.pieces.size();
    for (std::size_t k = 0; k < found; ++k) {
        const LitBox image = search.mirror(f.pieces[k]);
        if (std::none_of(f.pieces.begin(), f.pieces.begin() + static_cast<std::ptrdiff_t>(found),
                         [&](const LitBox& q) { return near(image, q, 2.0 * search.cell()); }))
            f.pieces.push_back(image);
    }
    f.all.extend(search.mirror(f.all));
}

Found findPieces(const RegionSearch& search) {
    const LitGrid coarse = search.coarse();
    Found f{litPieces(coarse, kMaxPieces), litBox(coarse), {}};
    addPoints(search, f, litPlaces(coarse));
    completeBySymmetry(search, f);
    return f;
}

PupilRegion withPoints(PupilRegion r, const std::vector<glm::dvec2>& points) {
    for (const glm::dvec2& p : points)
        if (std::abs(p.x - r.cx) <= r.half && std::abs(p.y - r.cy) <= r.half) r.litPoints.push_back(p);
    return r;
}

} // namespace ff::trace::detail
