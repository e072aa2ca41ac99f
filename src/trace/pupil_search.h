#pragma once
// The pupil search for callers that trace one path at several wavelengths and at a sequence of
// field angles (the ghost table, src/ghosts): the region of pupilRegion (trace/pupil_sampling.h) cut
// into parts where the light falls in pieces far apart, the searches at the wavelengths helping one
// another, and the pieces each search found, which the caller may hand to the search at another
// field angle as places to look (PupilHints). Which neighbours' pieces to hand over, and when, is
// the caller's policy; the search only looks where it is told.

#include "trace/pupil_sampling.h"

#include <span>
#include <vector>

namespace ff::trace {

/// The region of pupilRegion cut into parts where the path's light falls in pieces far apart (a
/// disc and, 18 mm from it, a band under 0.1 mm thick): one square per group of pieces (pieces closer
/// than 8 coarse cells join one group), each found by its own local passes, so that each gets a grid
/// at its own scale; one grid over the square holding both would put a row or two across the band,
/// and its moments would jitter from one field angle to the next. Not cut (one part, pupilRegion's
/// region) where there is one group or more than four, where the light is too broken up to tell its
/// pieces apart (over 64 pieces at the coarse spacing), where a group's light reaches its local
/// passes' outermost points, where the parts' squares would overlap, or where a jittered pass over
/// all the light, twice as dense as the local passes, finds light outside every part (a band between
/// the pieces that the coarse pass stepped over). The parts' squares never overlap, so their grids
/// count no light twice.
std::vector<PupilRegion> pupilParts(const PupilFrame& frame, const Field& field, Sampling sampling,
                                    const LensAtWavelength& L, const std::vector<PathStep>& steps,
                                    double maxRadiusMm = 0.0);

/// pupilParts at several wavelengths of the same field and path, [wavelength][part]. The searches help
/// one another: each places its coarse points independently of the others, and where one finds a piece
/// of light far from everything another found, the other looks for light there on a finer pass of its
/// own. A band a fraction of the coarse spacing thick is met by each search with a chance of its own;
/// where one search finds it, the others' finer passes find it too, if it is there at their
/// wavelengths (docs/sampling-cases.md, "Searches that help one another").
std::vector<std::vector<PupilRegion>> pupilPartsByWavelength(const PupilFrame& frame, const Field& field,
                                                             Sampling sampling, std::span<const LensAtWavelength> Ls,
                                                             const std::vector<PathStep>& steps,
                                                             double maxRadiusMm = 0.0);

/// A box of the pupil plane (mm) over a piece of light a search found.
struct PupilBox {
    double xMin = 0.0, xMax = 0.0, yMin = 0.0, yMax = 0.0;
};

/// Boxes to look at for light, [wavelength][box].
using PupilHints = std::vector<std::vector<PupilBox>>;

/// What searchPupil found at several wavelengths of one field and path.
struct PupilSearch {
    std::vector<std::vector<PupilRegion>> parts; ///< [wavelength][part], as pupilPartsByWavelength
    /// The pieces of light found, [wavelength][piece], for searches at neighbouring field angles to
    /// look at; none where no light was found, or where it is too broken up to tell its pieces apart
    /// (tooBroken).
    PupilHints pieces;
    std::vector<char> tooBroken; ///< [wavelength]
    double spacing = 0.0;        ///< the searches' nominal spacing (mm): pieces closer than two of it are one
    /// Whether looking at the hints found light far from everything the search had found without them.
    bool hintsFoundLight = false;
};

/// pupilPartsByWavelength, told where light was found at neighbouring field angles of the same path:
/// a piece of light a fraction of the coarse spacing across is met by the coarse passes with a chance
/// of its area over a cell's, so the searches of neighbouring angles step over it at some angles and
/// not at others, and a ghost's moments jump (docs/sampling-cases.md, "Hints from neighbouring
/// angles"). hints[w] (empty: none) are boxes where light was found at wavelength w; those far from
/// everything this search found are looked at on the finer passes that serve the wavelengths' hints
/// to one another. lookCloser: where such a pass finds nothing at a hint smaller than a coarse cell,
/// one as dense looks over the hint's box alone (a piece shrinking to nothing between two field
/// angles very close together).
PupilSearch searchPupil(const PupilFrame& frame, const Field& field, Sampling sampling,
                        std::span<const LensAtWavelength> Ls, const std::vector<PathStep>& steps,
                        double maxRadiusMm = 0.0, const PupilHints& hints = {}, bool lookCloser = false);

/// Whether the hints' looks of searchPupil find light far from what `known` (searchPupil's result at
/// this field, without these hints) found: the looks alone, without the coarse passes, to tell cheaply
/// whether searching again with the hints (and lookCloser) would find more.
bool hintsFindLight(const PupilFrame& frame, const Field& field, Sampling sampling,
                    std::span<const LensAtWavelength> Ls, const std::vector<PathStep>& steps, double maxRadiusMm,
                    const PupilSearch& known, const PupilHints& hints, bool lookCloser = false);

/// The pieces `from` found that lie far from every piece `of` found, [wavelength][piece] (none at a
/// wavelength where `of`'s light was too broken up to compare).
PupilHints piecesAwayFrom(const PupilSearch& from, const PupilSearch& of);

} // namespace ff::trace
