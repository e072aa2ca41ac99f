#pragma once
// Pupil sampling for a light source at infinity (the ray bundles themselves: trace/bundle.h).
//
// Sampling:
//  - ParaxialGrid: the grid covers the square circumscribing the paraxial entrance pupil, centred on
//    the axis for every field angle; rays outside the pupil disc are not launched.
//  - Reaim (default): a coarse pass, refined locally, finds where light actually gets through along
//    the given path (the real, vignetted pupil of that path at this field angle) and the grid covers
//    that region's bounding box, so every path gets its full resolution.
// Every launched ray stands for one grid cell of area cellArea (mm^2 in the pupil plane), so path
// energies are sums of weight x cellArea and compare across bundles.

#include "trace/bundle.h"
#include "trace/embree_tracer.h"

#include <glm/vec2.hpp>

#include <span>
#include <vector>

namespace ff::trace {

enum class Sampling { Reaim, ParaxialGrid };

/// The square of the pupil plane a path's grid covers: centre (cx, cy) and half side.
struct PupilRegion {
    double cx = 0.0, cy = 0.0, half = 0.0;
    bool discOnly = false; ///< launch only inside the paraxial pupil disc (paraxial-grid sampling)
    /// Share of the square the path's light passes (landing within the search's radius, if given;
    /// estimated on the finest analytic pass; 1 where not searched): a thin sliver of light needs a
    /// finer grid than a disc to be resolved.
    double litFraction = 1.0;
    /// Share of that pass's lit points with no lit neighbour on either side along x or along y: light
    /// at most one point thick there (thin bands and rings, the tips of slivers), which a grid of the
    /// same spacing lets slip between its rays; 0 where not searched.
    double thinShare = 0.0;
    /// The lit points (pupil plane, mm) in the square that the search's passes found (the coarse pass,
    /// the looks, the last local pass over the square, with their mirror images where the light is
    /// symmetric): light that a grid over the square must not let slip between its rays
    /// (measureBundleResolved); empty where not searched.
    std::vector<glm::dvec2> litPoints = {};
};

/// Half side of the square, centred on the axis, that the region search starts from: everything that
/// could enter the front surface at this field.
double searchHalfSize(const PupilFrame& frame, const Field& field);

/// Where the grid of one path goes, by the chosen sampling. For Reaim, a coarse analytic pass at L's
/// wavelength (jittered points an eighth of the pupil radius apart, up to 512 across, so that small
/// patches and thin rings of light are not stepped over), then local passes over what it found (until
/// no light reaches their outermost points), so that the region moves smoothly with the field angle;
/// its margin (1/96 of the coarse square) also covers the small shift of the pupil with wavelength, so
/// one region serves every wavelength of a path (where the lit shape changes with it, search at each). What
/// the coarse pass finds is completed by the light's mirror symmetry across the line through the axis
/// along the field's azimuth, where the iris is symmetric about that line (Iris::mirrorSymmetricAbout).
/// With maxRadiusMm > 0 only light landing within that radius of the axis counts as found: where the
/// rest of a ghost is not measured, its grid need not cover it.
PupilRegion pupilRegion(const PupilFrame& frame, const Field& field, Sampling sampling, const LensAtWavelength& L,
                        const std::vector<PathStep>& steps, double maxRadiusMm = 0.0);

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
/// angles"). hints[w] (empty: none) are boxes where light was found at
/// wavelength w; those far from everything this search found are looked at on the finer passes that
/// serve the wavelengths' hints to one another. lookCloser: where such a pass finds nothing at a hint
/// smaller than a coarse cell, one as dense looks over the hint's box alone (for a piece shrinking to
/// nothing, traced at the finest step of a ghost table).
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

/// One region for a band of wavelengths, for callers that trace all of them on the same grid: the
/// square over the regions searched at the band's shortest and longest wavelengths (first and last
/// of `ends`). A lit pupil can change shape with the wavelength, not only shift, and the indices,
/// which move its edges, change monotonically across a band; its lit fraction is the larger lit
/// area's share of that square, its thin share the larger one, its lit points both searches'.
PupilRegion bandRegion(const PupilFrame& frame, const Field& field, Sampling sampling,
                       std::span<const LensAtWavelength> ends, const std::vector<PathStep>& steps,
                       double maxRadiusMm = 0.0);

/// The n x n bundle over a region.
Bundle regionBundle(const PupilFrame& frame, const Field& field, const PupilRegion& region, int n);

/// The bundle for one path at one field and wavelength, by the chosen sampling.
Bundle makeBundle(const PupilFrame& frame, const Field& field, Sampling sampling, int n, const LensAtWavelength& L,
                  const std::vector<PathStep>& steps);

} // namespace ff::trace
