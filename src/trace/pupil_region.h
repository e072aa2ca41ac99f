#pragma once
// The square of the pupil plane that one path's grid covers, and the grid over it (the searches that
// place it: trace/pupil_sampling.h).

#include "trace/bundle.h"

#include <glm/vec2.hpp>

#include <vector>

namespace ff::trace {

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
    /// (the traced renderer's adaptive grids); empty where not searched.
    std::vector<glm::dvec2> litPoints = {};
};

/// Half side of the square, centred on the axis, that the region search starts from: everything that
/// could enter the front surface at this field.
double searchHalfSize(const PupilFrame& frame, const Field& field);

/// The n x n bundle over a region.
Bundle regionBundle(const PupilFrame& frame, const Field& field, const PupilRegion& region, int n);

} // namespace ff::trace
