#include "trace/pupil_search.h"

#include "trace/region_search.h"

#include <algorithm>

namespace ff::trace {

using detail::addPoints;
using detail::completeBySymmetry;
using detail::findPieces;
using detail::Found;
using detail::kMaxParts;
using detail::kMaxPieces;
using detail::kPartGapCells;
using detail::near;
using detail::partsFrom;
using detail::RegionSearch;

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

} // namespace ff::trace
