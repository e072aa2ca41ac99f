#pragma once
// An adaptively refined pupil grid for one path at one wavelength: the traced flare's cells.
//
// The grid starts as n x n square cells over a pupil square. Every cell has five traced samples, its
// four corners and its centre; a sample is a pupil point's landing position (pixels), its weight
// (Fresnel and coating factors) and whether it arrived. A cell is split into 2 x 2 children (its
// centre becomes their shared corner; the four edge midpoints and four child centres are traced, a
// point shared with a neighbour once) when
//  - the four triangles (corner, next corner, centre) do not share one orientation (the map folds
//    inside the cell: a caustic), while its footprint is larger than foldStopPx; or, while the
//    footprint is larger than stopPx,
//  - its samples do not share one fate (it straddles a vignetting edge), or
//  - the centre lands farther than linearRel x the footprint's extent from the corners' mean (the
//    map is not affine over the cell: with extent L and that distance d, its Jacobian, and so the
//    irradiance, changes by about 8 d / L across the cell), or
//  - the centre's weight differs from the corners' mean by more than weightRel of it;
// recursively, to maxDepth levels below the start or until the path's ray budget is spent (the cells
// with the largest footprints go first; budgetHit says when it bound). A cell whose footprint cannot
// reach the frame is not split: its light is counted, not drawn.
//
// Energy (mm^2 of pupil x weight) of a cell: its area x (w_centre / 2 + sum of corner weights / 8),
// lost samples weighing 0 (exact for a bilinear weight; at a vignetting edge it samples the lit share
// at five points). A fully lit cell (all five samples arrive) hands exactly its energy to its children,
// shared in proportion to their own estimates, so refining it moves light but never changes the flux;
// a cell straddling an edge is replaced by its children's own energies, which resolve the edge.
//
// Drawing a leaf: a fully lit, unfolded leaf is taken as affine on each of its four pupil triangles
// (corner, next corner, centre), each a quarter of the cell carrying a quarter of its energy (by the
// triangle's three weights), drawn with exact pixel-area coverage: the density follows the map's
// Jacobian from triangle to triangle. Any other lit leaf (folded at the last level, or straddling an
// edge) is drawn uniformly over the convex hull of its arriving samples, which the stop sizes keep
// near a pixel. Nothing is stretched towards a lost ray, and a fold is drawn as the cells on its two
// sides down to an eighth of a pixel, so caustics show no spokes.

#include "trace/flare_raster.h"

#include <glm/vec2.hpp>

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace ff::trace {

/// A traced pupil point: where it lands (pixels), its weight, whether it arrived.
struct PupilSample {
    glm::dvec2 px{0.0};
    double weight = 0.0;
    bool ok = false;
};

/// Traces pupil points (mm, in the pupil plane) into samples, one per point.
using PupilSampler = std::function<void(std::span<const glm::dvec2> pupilMm, std::span<PupilSample> out)>;

/// When to split a cell (see the header comment). refined(R) divides every tolerance by R, adds
/// log2(R) levels and multiplies the budget by R^2.
struct RefineSettings {
    double stopPx =
        1.0; ///< footprints this small (pixels, largest side of the box over the arriving samples) are leaves
    double foldStopPx = 0.125; ///< the same for a folded cell (a caustic's brightest pixels are made of them)
    double edgeStopPx = 2.0;   ///< a cell crossed by one vignetting edge this small is cut along it, not split
    double linearRel =
        0.01; ///< centre's distance from the corners' mean, as a share of the footprint's extent, that splits a cell
    double weightRel = 0.02;                      ///< centre weight against the corners' mean, relative
    int maxDepth = 10;                            ///< levels below the starting grid
    std::size_t rayBudget = std::size_t(1) << 21; ///< samples traced by one path's refinement, at most
    bool fatesOnly = false; ///< split only cells straddling a vignetting edge (energy only; footprints ignored)

    static RefineSettings refined(double R);
    /// For measuring a path's energy (the direct image's normaliser): only vignetting edges, 4 levels.
    static RefineSettings energyOnly();
};

struct AdaptiveStats {
    std::size_t samples = 0; ///< pupil points traced (start grid and refinement)
    std::size_t leaves = 0;  ///< lit leaves
    int depth = 0;           ///< deepest level reached below the start
    bool budgetHit = false;  ///< the ray budget stopped the refinement
};

class AdaptiveGrid {
  public:
    /// The n x n starting cells over the square [x0, x0 + n cell] x [y0, y0 + n cell] (pupil mm);
    /// launched (n x n, row-major; empty: all) skips cells whose centre is not launched. Traces the
    /// start grid's (n+1)^2 corners and launched centres.
    /// litHints: pupil points (mm) where a search found light; a cell holding one whose samples are
    /// all lost is split like one straddling an edge (light thinner than the cells between them).
    AdaptiveGrid(int n, double x0, double y0, double cellMm, const std::vector<char>& launched,
                 const RefineSettings& settings, PupilSampler sampler, std::span<const glm::dvec2> litHints = {});

    /// Splits cells by the settings until none qualifies, maxDepth is reached or the budget is spent.
    /// With a frame (width x height pixels), cells whose footprint cannot reach it are not split.
    void refine(int frameWidth = 0, int frameHeight = 0);
    /// Sum of the leaves' energies (mm^2 x weight).
    double energy() const;
    /// Draws every lit leaf, its energy multiplied by scale, into the raster.
    void draw(double scale, CoverageRaster& raster, RasterStats& stats) const;
    const AdaptiveStats& stats() const { return stats_; }

  private:
    struct Cell {
        std::uint32_t X = 0, Y = 0, size = 0; ///< lattice corner and side (lattice units)
        std::uint32_t s[5] = {};              ///< samples: corners (X,Y), (X+s,Y), (X+s,Y+s), (X,Y+s); centre
        std::int32_t firstChild = -1;         ///< its four children are firstChild .. firstChild + 3
        int level = 0;
        double energy = 0.0;
        double extentPx = 0.0; ///< footprint's extent, or an estimate from the parent where under two samples arrive
        std::int32_t cut = -1; ///< index in cuts_ of a cell cut along one vignetting edge
    };
    /// Where one vignetting edge crosses a cell's side: bisected between a lattice point whose ray
    /// arrives (a) and one whose ray is lost (b).
    struct Crossing {
        int side = 0; ///< the cell side from corner `side` to corner `side + 1`
        std::uint32_t aX = 0, aY = 0, bX = 0, bY = 0, aSample = 0;
        std::uint32_t cornerX = 0, cornerY = 0, cornerSample = 0; ///< the side's arriving corner
        int rounds = 0;                                           ///< bisection steps left
    };
    /// Where the crossing lands (pixels): from the last arriving point, on along the side to the middle
    /// of the last step, extrapolated linearly from the arriving corner.
    glm::dvec2 crossingPx(const Crossing& x) const;
    struct Cut {
        std::size_t cell = 0;
        Crossing x[2];
    };

    std::uint32_t sampleAt(std::uint32_t X, std::uint32_t Y);
    void traceQueued();
    double ownEnergy(const Cell& c) const;
    double footprintExtent(const Cell& c) const;
    bool wantsSplit(const Cell& c) const;
    bool offFrame(const Cell& c) const;
    /// The box (pixels) over the cell's arriving samples; returns how many arrived.
    int footprintBox(const Cell& c, glm::dvec2& lo, glm::dvec2& hi) const;
    bool crossedOnce(const Cell& c) const;
    bool holdsHint(const Cell& c) const;
    void splitLevels(std::vector<std::size_t> frontier);
    std::vector<std::size_t> cutEdges();
    void split(std::size_t cell);

    int n_;
    double x0_, y0_, cellMm_;
    std::uint32_t S_; ///< lattice units per starting cell
    RefineSettings settings_;
    int frameW_ = 0, frameH_ = 0; ///< the image (pixels) whose footprints matter; 0: unbounded
    PupilSampler sampler_;
    std::vector<PupilSample> samples_;
    /// Sample index by lattice point: open addressing, linear probing, a power-of-two table kept
    /// under half full (key ~0: empty).
    std::vector<std::pair<std::uint64_t, std::uint32_t>> index_;
    std::size_t indexed_ = 0;
    std::vector<glm::dvec2> queued_; ///< pupil points of samples created but not traced yet
    std::size_t queuedFrom_ = 0;     ///< index of the first queued sample
    std::vector<Cell> cells_;
    std::vector<Cut> cuts_;
    /// The lit hints in lattice units, by starting cell: those of cell k are hints_[hintStart_[k] ..
    /// hintStart_[k + 1]).
    std::vector<glm::dvec2> hints_;
    std::vector<std::uint32_t> hintStart_;
    AdaptiveStats stats_;
};

} // namespace ff::trace
