#pragma once
// The region search's lit points (internal to ff_trace: trace/region_search.h): passes of analytic rays over a
// square of the pupil plane, which of their points are lit, the boxes over lit points, and the pieces
// (groups of neighbouring lit points) they fall in.

#include "trace/bundle.h"
#include "trace/ghost_path.h"
#include "trace/sequential_tracer.h"

#include <glm/vec2.hpp>

#include <cstdint>
#include <optional>
#include <vector>

namespace ff::trace {

/// Bounding box of lit grid points, with what the region search needs to know of them.
struct LitBox {
    double xMin = 1e300, xMax = -1e300, yMin = 1e300, yMax = -1e300;
    bool touchesEdge = false;          ///< light at a grid point of the outermost ring
    double litArea = 0.0;              ///< lit points x cell area
    int litPoints = 0, thinPoints = 0; ///< lit points; those with no lit neighbour on either side along x or along y
    bool empty() const { return xMin > xMax; }
    /// Grows the box over o's extent only (counts and flags unchanged).
    void extend(const LitBox& o) {
        xMin = std::min(xMin, o.xMin), xMax = std::max(xMax, o.xMax);
        yMin = std::min(yMin, o.yMin), yMax = std::max(yMax, o.yMax);
    }
    void add(const LitBox& o) {
        extend(o);
        touchesEdge = touchesEdge || o.touchesEdge;
        litArea += o.litArea, litPoints += o.litPoints, thinPoints += o.thinPoints;
    }
};

/// Which points of b are lit: their rays arrive, within maxRadius of the axis (0: anywhere). A point
/// lies at its cell's centre, or, on a jittered pass, at its own place in its cell.
struct LitGrid {
    Bundle b;
    std::vector<char> lit;
    std::vector<glm::dvec2> offsets; ///< per point, in cells from its cell's centre (empty: none)
    bool at(int i, int j) const {
        return i >= 0 && j >= 0 && i < b.n && j < b.n && lit[static_cast<std::size_t>(j) * b.n + i];
    }
    glm::dvec2 point(int i, int j) const {
        const glm::dvec2 o = offsets.empty() ? glm::dvec2(0.0) : offsets[static_cast<std::size_t>(j) * b.n + i];
        return {b.x0 + (i + 0.5 + o.x) * b.cell, b.y0 + (j + 0.5 + o.y) * b.cell};
    }
};

/// Traces b's points (moved by their jitter, if a seed is given) and marks those lit.
LitGrid litGrid(Bundle b, const LensAtWavelength& L, const std::vector<PathStep>& steps, double maxRadius,
                std::optional<std::uint32_t> jitterSeed = std::nullopt);

/// The box over all of g's lit points.
LitBox litBox(const LitGrid& g);

/// The places of g's lit points.
std::vector<glm::dvec2> litPlaces(const LitGrid& g);

/// The pieces of light of a pass: the boxes of its groups of lit points linked through neighbours
/// (the eight around each), at most maxPieces of them (more: empty, the light is too broken up to
/// tell its pieces apart at this spacing).
std::vector<LitBox> litPieces(const LitGrid& g, std::size_t maxPieces);

/// The boxes' gap: how far apart they lie along x or y (negative where they overlap along both).
double gap(const LitBox& a, const LitBox& b);

} // namespace ff::trace
