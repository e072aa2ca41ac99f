#pragma once
// Where the light of a pupil cell passes between its traced rays. A ray traced with every aperture
// open (the iris and the clear apertures ignored; a miss or total internal reflection still ends it)
// carries, at each step, its hit's margin inside that surface's aperture: a smooth function of the
// pupil point whose zero line is the aperture's edge there. A path's light passes where every margin
// is non-negative (and the landing point lies within the counting radius, one more margin), so over
// a cell small enough for the margins to be linear the lit part is the square cut by one half-plane
// per margin: its area is exact for straight edges however thin the light between two of them, where
// whole sub-cells counted all or nothing (docs/sampling-cases.md, "Lit shares"). Units: mm; u, v in
// cells.

#include "trace/embree_tracer.h"
#include "trace/pupil_sampling.h"

#include <span>
#include <vector>

namespace ff::trace {

/// Rays traced with every aperture open: each ray's result as if nothing clipped it (Embree's
/// blocking geometry, the barrel, is not traced either) and its margins, steps per ray.
struct OpenTrace {
    std::size_t steps = 0;
    std::vector<RayResult> hits;
    std::vector<double> margins; ///< [ray * steps + step], mm: +inf unclipped, NaN past the step that ended the ray

    double margin(std::size_t ray, std::size_t step) const { return margins[ray * steps + step]; }
};

OpenTrace traceOpen(const LensAtWavelength& L, const std::vector<PathStep>& steps, std::span<const optics::Ray> rays);

/// A linear constraint value + du u + dv v >= 0 over the cell [-1/2, 1/2]^2.
struct HalfPlane {
    double value = 0.0, du = 0.0, dv = 0.0;
};

/// The share of the cell [-1/2, 1/2]^2 meeting every constraint (the square clipped by each
/// half-plane in turn, then its area), and where given and the share is not 0, the centroid of that
/// part (u, v).
double feasibleShare(std::span<const HalfPlane> constraints, glm::dvec2* centroid = nullptr);

/// The share of each sub-cell of a sub x sub grid (row-major, t's rays from first on) whose light passes: its
/// margins, and maxRadius - |landing point| where maxRadius > 0, each linear across the sub-cell with
/// the slopes of its neighbours along the grid's axes (central where both were traced through that
/// step, one-sided where one was, flat where neither). 0 where the ray's open trace ended. Where
/// centroids is given, it receives each lit part's centroid (u, v in sub-cells from the sub-ray).
std::vector<double> subCellShares(const OpenTrace& t, std::size_t first, int sub, double maxRadius,
                                  std::vector<glm::dvec2>* centroids = nullptr);

/// Sub-grids traced for the lit shares of their sub-cells: grid q has subs[q] x subs[q] rays (row-major,
/// parallel, as gridBundle lays them) from first[q] on. Each ray is traced open and its sub-cell's
/// share is subCellShares'. The light of each sub-cell with a share is then traced by the Embree
/// tracer: through the sub-ray itself where every aperture passes it and it lands within maxRadius,
/// else through the centroid of the sub-cell's lit part. That ray's hit stands for the lit part (its
/// landing point and weight); where it does not arrive or lands beyond maxRadius (the barrel, which
/// the open trace does not know, blocks it; or the margins are far from linear across the sub-cell,
/// as near a fold of the landing map) the share is 0.
struct SubGridTrace {
    std::vector<RayResult> hits;
    std::vector<double> share;
};

SubGridTrace traceSubGrids(const EmbreeTracer& tracer, const LensAtWavelength& L, const std::vector<PathStep>& steps,
                           std::span<const optics::Ray> rays, std::span<const std::size_t> first,
                           std::span<const int> subs, double maxRadius);

/// Whether a cell may hold light between its five rays, all of them dark: from the open traces of its
/// centre (t's ray first) and corners (the next four: (-,-), (+,-), (-,+), (+,+) in u, v), each margin linear across
/// the cell with the corners' slopes, relaxed by how far the centre lies from the corners' mean (the
/// margin's curvature across the cell). False where any of the five open traces ended.
bool mayHoldLight(const OpenTrace& t, std::size_t first, double maxRadius);

/// The cells of a grid (centre rays c of `centres`, corner rays k laid out as cornerBundle lays them)
/// that may hold light between their five rays: of the launched cells not `taken`, those none of
/// whose five rays counts (arrives, within maxRadius where > 0) whose rays were lost for different
/// reasons (clipped at different steps, lost otherwise, landing beyond the circle) — two edges cross
/// such a cell — and whose five rays' open traces leave room for light between them (mayHoldLight).
std::vector<std::size_t> cellsWithRoomForLight(const LensAtWavelength& L, const std::vector<PathStep>& steps,
                                               const PupilFrame& pupil, const Field& field, const Bundle& centres,
                                               const std::vector<RayResult>& c, const std::vector<RayResult>& k,
                                               double maxRadius, const std::vector<char>& taken);

} // namespace ff::trace
