#include "trace/pupil_sampling.h"

#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/lit_points.h"

#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>

namespace ff::trace {

namespace {

// The region search's shared steps, for one field and path: the coarse pass, the local passes that
// find a box's extent at their finer spacing, and the square over a box.
class RegionSearch {
  public:
    RegionSearch(const PupilFrame& frame, const Field& field, const LensAtWavelength& L,
                 const std::vector<PathStep>& steps, double maxRadius)
        : frame_(frame), field_(field), L_(L), steps_(steps), maxRadius_(maxRadius),
          half_(searchHalfSize(frame, field)), cell_(2.0 * half_ / kNominal),
          symmetric_(L.iris.mirrorSymmetricAbout(field.azimuthRad + 0.5 * std::numbers::pi)) {}

    // Coarse pass over everything that could enter the front surface, traced analytically. The
    // margins below are in cells of a 96 x 96 pass over it. The pass itself is denser where the
    // paraxial pupil is small against that square (a retrofocus wide angle's front opening dwarfs its
    // pupil): its spacing is an eighth of the pupil's radius (the scale of a ghost's own pupil; up to
    // 512 points across), or it steps over whole patches of light, or thin rings of it, at some field
    // angles and not others. Its points are jittered, each at a fixed place of its own in its cell:
    // light in a band thinner than the spacing and lying along the grid's rows or columns falls
    // between every point of a regular grid at some field angles, while each jittered point catches
    // it with a chance of its thickness over the spacing, so a band a few cells long is found at most
    // angles (docs/sampling-cases.md, "Bands along the grid"); findPieces completes what it found by
    // symmetry. Searches of the same field at other wavelengths pass other seeds, so that
    // each places its points independently of the others and a band one misses another is likely
    // to meet (pupilPartsByWavelength).
    LitGrid coarse(std::uint32_t seed = 0) const {
        const int n = std::clamp(static_cast<int>(std::ceil(16.0 * half_ / frame_.radius)), kNominal, kMaxCoarse);
        return litGrid(gridBundle(frame_, field_, n, 0.0, 0.0, half_, false), L_, steps_, maxRadius_, seed);
    }

    // A jittered n x n pass over the square around the box, two coarse cells wider on every side.
    LitGrid jittered(const LitBox& box, int n) const {
        const double h = 0.5 * std::max(box.xMax - box.xMin, box.yMax - box.yMin) + 2.0 * cell_;
        return litGrid(
            gridBundle(frame_, field_, n, 0.5 * (box.xMin + box.xMax), 0.5 * (box.yMin + box.yMax), h, false), L_,
            steps_, maxRadius_, kLookSeed);
    }

    // Whether light is at this wavelength where another's search found a piece: a jittered local pass
    // over the piece's box. The pieces of light it finds; its lit points are added to lit.
    // A piece much smaller than a coarse cell (a patch of light shrinking to nothing as the field
    // angle moves; docs/sampling-cases.md, "Vanishing patches") falls between the points of a pass
    // two coarse cells wider than it on every side: told to look closer, where that pass finds
    // nothing, a second one looks over the piece's box and as much again on every side.
    std::vector<LitBox> look(const LitBox& hint, std::size_t maxPieces, std::vector<glm::dvec2>& lit,
                             bool closer = false) const {
        LitGrid g = jittered(hint, kLocal);
        std::vector<glm::dvec2> places = litPlaces(g);
        const double side = std::max(hint.xMax - hint.xMin, hint.yMax - hint.yMin);
        if (closer && places.empty() && side < cell_) {
            const double h = 1.5 * std::max(side, 0.1 * cell_);
            g = litGrid(gridBundle(frame_, field_, kLocal, 0.5 * (hint.xMin + hint.xMax), 0.5 * (hint.yMin + hint.yMax),
                                   h, false),
                        L_, steps_, maxRadius_, kLookSeed);
            places = litPlaces(g);
        }
        lit.insert(lit.end(), places.begin(), places.end());
        return litPieces(g, maxPieces);
    }

    // A jittered pass over the box twice as dense as the local passes, for light they step over.
    LitGrid check(const LitBox& box) const { return jittered(box, 2 * kLocal); }

    // The coarse points miss the tips of thin regions (two discs barely overlapping), and the box would
    // jump by a coarse cell, cutting off light, as the field angle moves them across the points. A local
    // pass over the box (two cells wider on every side, wider still while light reaches its outermost
    // points) finds the extent at its finer spacing.
    // The lit points of the last pass that found light go to *lit, if given.
    LitBox refine(const LitBox& found, std::vector<glm::dvec2>* lit = nullptr) const {
        double cx = 0.5 * (found.xMin + found.xMax), cy = 0.5 * (found.yMin + found.yMax);
        double h = 0.5 * std::max(found.xMax - found.xMin, found.yMax - found.yMin) + 2.0 * cell_;
        LitBox box = found;
        for (int pass = 0; pass < 4; ++pass) {
            const LitGrid grid = litGrid(gridBundle(frame_, field_, kLocal, cx, cy, h, false), L_, steps_, maxRadius_);
            const LitBox local = litBox(grid);
            if (local.empty()) break;
            box = local;
            if (lit) *lit = litPlaces(grid);
            if (!local.touchesEdge) break;
            cx = 0.5 * (local.xMin + local.xMax), cy = 0.5 * (local.yMin + local.yMax);
            h = 0.5 * std::max(local.xMax - local.xMin, local.yMax - local.yMin) + 4.0 * cell_;
        }
        // Never less than the coarse pass found: light thinner than the local spacing can fall
        // between its points.
        box.xMin = std::min(box.xMin, found.xMin), box.xMax = std::max(box.xMax, found.xMax);
        box.yMin = std::min(box.yMin, found.yMin), box.yMax = std::max(box.yMax, found.yMax);
        // Where the light is its own mirror image, so is light that crosses the mirror line: its box
        // holds its image. The passes meet a band thinner than their spacing at some of its points
        // and not others, and the box over those can stop short of one end (docs/sampling-cases.md,
        // "Bands across the mirror line").
        if (symmetric_) {
            const LitBox image = mirror(box);
            if (gap(box, image) < 0.0) box.extend(image);
        }
        return box;
    }

    // One cell of margin on every side, then a square over the box, holding the lit points given.
    PupilRegion square(const LitBox& box, std::vector<glm::dvec2> lit = {}) const {
        const double side = std::max(box.xMax - box.xMin, box.yMax - box.yMin) + 2.0 * cell_;
        return {0.5 * (box.xMin + box.xMax),
                0.5 * (box.yMin + box.yMax),
                0.5 * side,
                false,
                std::min(1.0, box.litArea / (side * side)),
                double(box.thinPoints) / box.litPoints,
                std::move(lit)};
    }

    // The square over what local passes find around a box the coarse pass found, with their lit points.
    PupilRegion region(const LitBox& found) const {
        std::vector<glm::dvec2> lit;
        const LitBox box = refine(found, &lit);
        return square(box, std::move(lit));
    }

    // Whether the field's light is mirror-symmetric across the line through the axis along the field's
    // azimuth: the surfaces and the barrel are surfaces of revolution, so it is unless the iris's
    // blades are not symmetric about that line.
    bool symmetric() const { return symmetric_; }

    // A point's mirror image across that line.
    glm::dvec2 mirror(glm::dvec2 p) const {
        const glm::dvec2 e(-std::sin(field_.azimuthRad), std::cos(field_.azimuthRad));
        return 2.0 * (p.x * e.x + p.y * e.y) * e - p;
    }

    // The box's mirror image across that line: the box over its corners' images (the same box where
    // the azimuth is a multiple of 90 deg), the same counts.
    LitBox mirror(const LitBox& b) const {
        LitBox m = b;
        m.xMin = m.yMin = 1e300, m.xMax = m.yMax = -1e300;
        for (const glm::dvec2 p : {glm::dvec2(b.xMin, b.yMin), glm::dvec2(b.xMax, b.yMin), glm::dvec2(b.xMin, b.yMax),
                                   glm::dvec2(b.xMax, b.yMax)}) {
            const glm::dvec2 q = mirror(p);
            m.xMin = std::min(m.xMin, q.x), m.xMax = std::max(m.xMax, q.x);
            m.yMin = std::min(m.yMin, q.y), m.yMax = std::max(m.yMax, q.y);
        }
        return m;
    }

    double cell() const { return cell_; }

  private:
    static constexpr int kNominal = 96, kMaxCoarse = 512, kLocal = 64;
    static constexpr std::uint32_t kLookSeed = 0xA5A5u;
    const PupilFrame& frame_;
    const Field& field_;
    const LensAtWavelength& L_;
    const std::vector<PathStep>& steps_;
    double maxRadius_, half_, cell_;
    bool symmetric_;
};

// Pieces of light closer than this many cells of the nominal coarse pass share a part; a region is
// cut into at most kMaxParts parts (light in more groups is traced on one grid).
constexpr double kPartGapCells = 8.0;
constexpr std::size_t kMaxParts = 4;

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

double searchHalfSize(const PupilFrame& frame, const Field& field) {
    const double shift = std::abs(std::tan(field.angleRad)) * std::abs(frame.z - frame.startZ);
    return std::max(frame.frontRadius, frame.radius) + shift + frame.radius;
}

namespace {

constexpr std::size_t kMaxPieces = 64;

// What a coarse pass found: its pieces of light (none where there are more than kMaxPieces, too broken
// up to tell apart), the box over all of it, and the lit points of it and of the looks that added to it
// (with their mirror images, where the light is symmetric): the parts' grids must not let the light
// at any of them slip between their rays (PupilRegion::litPoints).
struct Found {
    std::vector<LitBox> pieces;
    LitBox all;
    std::vector<glm::dvec2> points;
};

// Adds a pass's lit points to what was found, with their images where the light is symmetric.
void addPoints(const RegionSearch& search, Found& f, const std::vector<glm::dvec2>& places) {
    f.points.insert(f.points.end(), places.begin(), places.end());
    if (search.symmetric())
        for (const glm::dvec2& p : places) f.points.push_back(search.mirror(p));
}

// Whether b lies within `margin` of a (their boxes, each widened by margin, overlap).
bool near(const LitBox& a, const LitBox& b, double margin) {
    return gap(a, b) < margin;
}

// Completes what was found by symmetry: the light is its own mirror image (RegionSearch::mirror), so
// a piece whose image is far from every piece found was met on one side and stepped over on the
// other (jittered points fall differently on the two sides, which doubles the chances of meeting a
// thin band that crosses the mirror line, or one of a mirrored pair), and the image is added as a
// piece of its own.
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

// The coarse pass's pieces, completed by symmetry.
Found findPieces(const RegionSearch& search, std::uint32_t seed) {
    const LitGrid coarse = search.coarse(seed);
    Found f{litPieces(coarse, kMaxPieces), litBox(coarse), {}};
    addPoints(search, f, litPlaces(coarse));
    completeBySymmetry(search, f);
    return f;
}

// The region with those of the points that lie in its square added to its lit points.
PupilRegion withPoints(PupilRegion r, const std::vector<glm::dvec2>& points) {
    for (const glm::dvec2& p : points)
        if (std::abs(p.x - r.cx) <= r.half && std::abs(p.y - r.cy) <= r.half) r.litPoints.push_back(p);
    return r;
}

// The parts of pupilParts from the pieces found.
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

} // namespace

PupilRegion pupilRegion(const PupilFrame& frame, const Field& field, Sampling sampling, const LensAtWavelength& L,
                        const std::vector<PathStep>& steps, double maxRadiusMm) {
    if (sampling == Sampling::ParaxialGrid) return {0.0, 0.0, frame.radius, true};
    const RegionSearch search(frame, field, L, steps, maxRadiusMm);
    const Found found = findPieces(search, 0);
    if (found.all.empty()) return {0.0, 0.0, frame.radius, true}; // nothing gets through: the paraxial pupil
    return withPoints(search.region(found.all), found.points);
}

std::vector<PupilRegion> pupilParts(const PupilFrame& frame, const Field& field, Sampling sampling,
                                    const LensAtWavelength& L, const std::vector<PathStep>& steps, double maxRadiusMm) {
    return pupilPartsByWavelength(frame, field, sampling, std::span<const LensAtWavelength>(&L, 1), steps, maxRadiusMm)
        .front();
}

namespace {

LitBox litBoxOf(const PupilBox& b) {
    LitBox l;
    l.xMin = b.xMin, l.xMax = b.xMax, l.yMin = b.yMin, l.yMax = b.yMax;
    return l;
}

bool tooBroken(const Found& f) {
    return f.pieces.empty() && !f.all.empty();
}

// Looks at the hints (pieces of light found elsewhere) lying far from every piece `mine` holds, unless
// they fall in more groups than a region is cut into, and adds the pieces of light found there.
// Returns whether any of those lies far from every piece `mine` held before.
bool lookAt(const RegionSearch& search, Found& mine, std::vector<LitBox> hints, bool closer = false) {
    const double margin = 2.0 * search.cell();
    const std::vector<LitBox> before = mine.pieces;
    const auto known = [&](const LitBox& p) {
        return std::any_of(before.begin(), before.end(), [&](const LitBox& q) { return near(p, q, margin); });
    };
    std::erase_if(hints, known);
    hints = mergeNear(std::move(hints), kPartGapCells * search.cell());
    if (hints.size() > kMaxParts) return false;
    bool more = false;
    std::vector<glm::dvec2> lit;
    for (const LitBox& h : hints)
        for (const LitBox& p : search.look(h, kMaxPieces, lit, closer)) {
            more = more || !known(p);
            mine.pieces.push_back(p);
            mine.all.add(p);
        }
    addPoints(search, mine, lit);
    return more;
}

std::vector<LitBox> litBoxes(const std::vector<PupilBox>& boxes) {
    std::vector<LitBox> out;
    for (const PupilBox& b : boxes) out.push_back(litBoxOf(b));
    return out;
}

} // namespace

PupilSearch searchPupil(const PupilFrame& frame, const Field& field, Sampling sampling,
                        std::span<const LensAtWavelength> Ls, const std::vector<PathStep>& steps, double maxRadiusMm,
                        const PupilHints& hints, bool lookCloser) {
    PupilSearch out;
    out.pieces.assign(Ls.size(), {});
    out.tooBroken.assign(Ls.size(), 0);
    if (sampling == Sampling::ParaxialGrid) {
        out.parts.assign(Ls.size(), {{0.0, 0.0, frame.radius, true}});
        return out;
    }
    std::vector<RegionSearch> searches;
    searches.reserve(Ls.size());
    std::vector<Found> found;
    for (std::size_t w = 0; w < Ls.size(); ++w) {
        searches.emplace_back(frame, field, Ls[w], steps, maxRadiusMm);
        found.push_back(findPieces(searches[w], static_cast<std::uint32_t>(w)));
    }
    out.spacing = Ls.empty() ? 0.0 : searches.front().cell();
    for (std::size_t w = 0; w < Ls.size(); ++w) {
        Found mine = found[w];
        // The pieces other wavelengths found with nothing of this one's near them (light shifts a
        // little with the wavelength; a piece far from all of this one's was stepped over, or is not
        // there at this wavelength) are looked at again, unless the light is too broken up to tell
        // its pieces apart; then those found at neighbouring field angles.
        if (!tooBroken(mine)) {
            std::vector<LitBox> shared;
            for (std::size_t v = 0; v < Ls.size(); ++v)
                if (v != w) shared.insert(shared.end(), found[v].pieces.begin(), found[v].pieces.end());
            lookAt(searches[w], mine, std::move(shared));
            if (w < hints.size() && lookAt(searches[w], mine, litBoxes(hints[w]), lookCloser))
                out.hintsFoundLight = true;
        }
        completeBySymmetry(searches[w], mine); // what the looks found, too
        out.parts.push_back(partsFrom(searches[w], frame, mine));
        out.tooBroken[w] = tooBroken(mine);
        for (const LitBox& p : mine.pieces) out.pieces[w].push_back({p.xMin, p.xMax, p.yMin, p.yMax});
    }
    return out;
}

std::vector<std::vector<PupilRegion>> pupilPartsByWavelength(const PupilFrame& frame, const Field& field,
                                                             Sampling sampling, std::span<const LensAtWavelength> Ls,
                                                             const std::vector<PathStep>& steps, double maxRadiusMm) {
    return searchPupil(frame, field, sampling, Ls, steps, maxRadiusMm).parts;
}

bool hintsFindLight(const PupilFrame& frame, const Field& field, Sampling sampling,
                    std::span<const LensAtWavelength> Ls, const std::vector<PathStep>& steps, double maxRadiusMm,
                    const PupilSearch& known, const PupilHints& hints, bool lookCloser) {
    if (sampling == Sampling::ParaxialGrid) return false;
    for (std::size_t w = 0; w < Ls.size() && w < hints.size(); ++w) {
        if (hints[w].empty() || (w < known.tooBroken.size() && known.tooBroken[w])) continue;
        const RegionSearch search(frame, field, Ls[w], steps, maxRadiusMm);
        Found mine;
        if (w < known.pieces.size()) mine.pieces = litBoxes(known.pieces[w]);
        for (const LitBox& p : mine.pieces) mine.all.extend(p);
        if (lookAt(search, mine, litBoxes(hints[w]), lookCloser)) return true;
    }
    return false;
}

PupilHints piecesAwayFrom(const PupilSearch& from, const PupilSearch& of) {
    const double margin = 2.0 * std::max(from.spacing, of.spacing);
    PupilHints out(from.pieces.size());
    for (std::size_t w = 0; w < from.pieces.size(); ++w) {
        if (w < of.tooBroken.size() && of.tooBroken[w]) continue;
        const std::vector<LitBox> mine = w < of.pieces.size() ? litBoxes(of.pieces[w]) : std::vector<LitBox>{};
        for (const PupilBox& b : from.pieces[w]) {
            const LitBox p = litBoxOf(b);
            if (std::none_of(mine.begin(), mine.end(), [&](const LitBox& q) { return near(p, q, margin); }))
                out[w].push_back(b);
        }
    }
    return out;
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

Bundle regionBundle(const PupilFrame& frame, const Field& field, const PupilRegion& r, int n) {
    return gridBundle(frame, field, n, r.cx, r.cy, r.half, r.discOnly);
}

Bundle makeBundle(const PupilFrame& frame, const Field& field, Sampling sampling, int n, const LensAtWavelength& L,
                  const std::vector<PathStep>& steps) {
    return regionBundle(frame, field, pupilRegion(frame, field, sampling, L, steps), n);
}

} // namespace ff::trace
