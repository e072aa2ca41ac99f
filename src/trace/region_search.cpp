#include "trace/region_search.h"

#include <algorithm>
#include <cmath>

namespace ff::trace::detail {

namespace {

bool overlap(const PupilRegion& a, const PupilRegion& b) {
    return std::abs(a.cx - b.cx) < a.half + b.half && std::abs(a.cy - b.cy) < a.half + b.half;
}

// A part's square is as wide as its box's longer side (RegionSearch::square), so along the shorter
// side it may slide without uncovering its box: its centre may lie anywhere in [box max + margin -
// half, box min - margin + half] along each axis.
struct Slide {
    double lo, hi;
};

Slide slide(double boxMin, double boxMax, double half, double margin) {
    return {boxMax + margin - half, boxMin - margin + half};
}

// Slides overlapping squares apart along an axis on which their boxes lie apart, each within its own
// slack: two pieces far apart whose boxes are long across the gap between them get squares reaching
// over it (docs/sampling-cases.md, "Pieces far apart"). Returns whether no two squares overlap.
bool slideApart(std::vector<PupilRegion>& parts, const std::vector<LitBox>& boxes, double margin) {
    const auto separate = [&](std::size_t a, std::size_t b, bool alongY) {
        double& ca = alongY ? parts[a].cy : parts[a].cx;
        double& cb = alongY ? parts[b].cy : parts[b].cx;
        const auto span = [&](std::size_t k) {
            return alongY ? slide(boxes[k].yMin, boxes[k].yMax, parts[k].half, margin)
                          : slide(boxes[k].xMin, boxes[k].xMax, parts[k].half, margin);
        };
        const double loA = alongY ? boxes[a].yMin : boxes[a].xMin, loB = alongY ? boxes[b].yMin : boxes[b].xMin;
        const bool aAbove = loA > loB;
        const std::size_t up = aAbove ? a : b, down = aAbove ? b : a;
        double& cu = aAbove ? ca : cb;
        double& cd = aAbove ? cb : ca;
        const double need = parts[up].half + parts[down].half;
        if (span(up).hi - span(down).lo < need) return false;
        const double deficit = need * (1.0 + 1e-12) - (cu - cd); // touching squares do not overlap
        if (deficit <= 0.0) return true;
        const double moveUp = std::min(deficit, std::max(0.0, span(up).hi - cu));
        cu += moveUp;
        cd -= deficit - moveUp;
        return true;
    };
    for (int round = 0; round < 4; ++round) {
        bool any = false;
        for (std::size_t a = 0; a < parts.size(); ++a)
            for (std::size_t b = a + 1; b < parts.size(); ++b)
                if (overlap(parts[a], parts[b])) {
                    any = true;
                    if (!separate(a, b, true)) separate(a, b, false);
                }
        if (!any) return true;
    }
    for (std::size_t a = 0; a < parts.size(); ++a)
        for (std::size_t b = a + 1; b < parts.size(); ++b)
            if (overlap(parts[a], parts[b])) return false;
    return true;
}

} // namespace

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

Found findPieces(const RegionSearch& search, std::uint32_t seed) {
    const LitGrid coarse = search.coarse(seed);
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

std::vector<PupilRegion> partsFrom(const RegionSearch& search, const PupilFrame& frame, const Found& found) {
    if (found.all.empty()) return {{0.0, 0.0, frame.radius, true}}; // nothing gets through: the paraxial pupil
    const std::vector<LitBox> groups = mergeNear(found.pieces, kPartGapCells * search.cell());
    if (groups.size() < 2 || groups.size() > kMaxParts) return {withPoints(search.region(found.all), found.points)};
    // Each group's extent found by its own local passes.
    std::vector<PupilRegion> parts;
    std::vector<LitBox> boxes;
    bool split = true;
    for (const LitBox& g : groups) {
        std::vector<glm::dvec2> lit;
        boxes.push_back(search.refine(g, &lit));
        if (boxes.back().touchesEdge) split = false; // light beyond the local passes: the part's extent is not known
        parts.push_back(search.square(boxes.back(), std::move(lit)));
    }
    split = split && slideApart(parts, boxes, search.cell());
    // Light between the groups that the coarse pass stepped over would be lost to every part
    // (docs/sampling-cases.md, "Bands between groups"). A jittered pass over all the light, twice
    // as dense as the local passes, must find every lit point within the parts, or the region is not
    // cut.
    std::vector<glm::dvec2> wholeLit;
    const LitBox wholeBox = search.refine(found.all, &wholeLit);
    std::vector<glm::dvec2> points = found.points;
    if (split) {
        const LitGrid whole = search.check(wholeBox);
        const std::vector<glm::dvec2> checked = litPlaces(whole);
        points.insert(points.end(), checked.begin(), checked.end());
        for (int j = 0; j < whole.b.n && split; ++j)
            for (int i = 0; i < whole.b.n && split; ++i) {
                if (!whole.at(i, j)) continue;
                const glm::dvec2 p = whole.point(i, j);
                split = std::any_of(parts.begin(), parts.end(), [&](const PupilRegion& r) {
                    return std::abs(p.x - r.cx) <= r.half && std::abs(p.y - r.cy) <= r.half;
                });
            }
    }
    if (split) {
        for (PupilRegion& part : parts) part = withPoints(std::move(part), points);
        return parts;
    }
    return {withPoints(search.square(wholeBox, std::move(wholeLit)), points)};
}

} // namespace ff::trace::detail
