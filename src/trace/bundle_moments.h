#pragma once
// Energy, centroid and second moments of a traced bundle on the sensor: the one place the ghost
// report, the traced renderer, the ghost fits and the ghost table measure a path's light.

#include "trace/embree_tracer.h"
#include "trace/pupil_sampling.h"

#include <span>
#include <vector>

namespace ff::trace {

struct BundleMoments {
    std::size_t launched = 0, surviving = 0, blocked = 0; ///< ray counts over launched rays
    double energy = 0.0;                                  ///< sum of weight x cell area x scale over the counted rays
    double centroidX = 0.0, centroidY = 0.0;              ///< energy-weighted, mm
    double mxx = 0.0, myy = 0.0, mxy = 0.0;               ///< central second moments, mm^2
};

/// Measures the surviving rays; when maxRadiusMm > 0 only those landing within it of the axis count
/// towards energy and moments (the counts still cover every surviving ray).
BundleMoments measureBundle(const Bundle& bundle, const std::vector<RayResult>& hits, double scale = 1.0,
                            double maxRadiusMm = 0.0);

/// The same over samples that stand for pupil areas of their own (area 0: not launched).
BundleMoments measureSamples(std::span<const RayResult> hits, std::span<const double> areas, double scale,
                             double maxRadiusMm);

/// The moments of the union of disjoint sets of samples (the parts of a path's pupil, each on its own
/// grid) from theirs: energies and counts add, the centroid is the energy-weighted mean, and each
/// part's second moments move to the common centroid by the parallel-axis rule.
BundleMoments combineMoments(std::span<const BundleMoments> parts);

/// measureBundle with the vignetting edges resolved below the grid. A cell whose centre and corner
/// rays (cornerBundle) do not share one fate — lost or arriving, landing inside maxRadiusMm or not —
/// straddles an edge that a single centre ray counts all or nothing of, so the moments would move in
/// steps as the field angle sweeps the edge across cells; here each such cell is re-traced on a
/// `subdivisions` x `subdivisions` sub-grid, each sub-ray standing for the lit share of its sub-cell
/// (traceSubGrids: the sub-cell cut by each aperture's edge and the counting circle, from the open
/// traces' margins; exact for straight edges, however thin the light between two of them). So is, in
/// turn, every dark cell (none of its five rays counts) into which a sub-grid's light reaches (light
/// thinner than the grid passing between all five of its rays), every dark cell whose open traces
/// leave room for light between two edges (cellsWithRoomForLight), every cell whose five rays all
/// count but whose weights differ more than two-fold (a step in the weight: a reflection turning
/// total), and every dark cell holding one of litPoints (points known to be lit, e.g. the region
/// search's: light passing between all five rays of cells that no straddling cell borders). Light in
/// a dark cell is thin, so dark cells get sub-grids twice as dense. Any other cell all of whose five
/// rays count is integrated by 2/3 of its centre ray plus 1/3 of its corners' mean (fourth order: the
/// h^2 terms of the midpoint and trapezoid rules cancel). Counts (launched, surviving, blocked) stay
/// those of the grid's centre rays.
BundleMoments measureBundleResolved(const EmbreeTracer& tracer, const LensAtWavelength& L,
                                    const std::vector<PathStep>& steps, const PupilFrame& pupil, const Field& field,
                                    const Bundle& centres, const std::vector<RayResult>& centreHits,
                                    const std::vector<RayResult>& cornerHits, int subdivisions, double scale = 1.0,
                                    double maxRadiusMm = 0.0, std::span<const glm::dvec2> litPoints = {});

} // namespace ff::trace
