#pragma once
// One shaped ghost instance's mesh at one wavelength placed in the frame (internal to ff_ghosts):
// interpolated between the table's fields, turned and mirrored into the frame's pixels, with its
// constraints and Jacobians; shaped_mesh.cpp cuts it into the polygons it is drawn as.

#include "ghosts/shaped_ghosts.h"
#include "trace/flare_raster.h"

#include <array>
#include <cstddef>
#include <limits>
#include <vector>

namespace ff::ghosts {

// Catmull-Rom weights of the four samples around a position u in [0, 1] between the middle two.
inline std::array<double, 4> catmullRom(double u) {
    const double u2 = u * u, u3 = u2 * u;
    return {0.5 * (-u + 2 * u2 - u3), 0.5 * (2 - 5 * u2 + 3 * u3), 0.5 * (u + 4 * u2 - 3 * u3), 0.5 * (-u2 + u3)};
}

// Their derivatives in u.
inline std::array<double, 4> catmullRomSlope(double u) {
    const double u2 = u * u;
    return {0.5 * (-1 + 4 * u - 3 * u2), 0.5 * (-10 * u + 9 * u2), 0.5 * (1 + 8 * u - 9 * u2), 0.5 * (-2 * u + 3 * u2)};
}

// One instance's mesh at one wavelength, interpolated in angle and placed in the frame: per vertex S
// doubles, pixel x, y, weight, the C constraints' values, then the map's Jacobian (pixels^2 per cell;
// NaN where it cannot be taken).
struct MeshVertices {
    int n = 0; ///< cells per side
    std::size_t C = 0, J = 0, S = 0;
    std::vector<double> attr;
    std::vector<char> ok; ///< the vertex's ray lands
    double xMin = std::numeric_limits<double>::infinity(), xMax = -xMin, yMin = xMin, yMax = -xMin;

    std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * (n + 1) + i; }
    const double* at(std::size_t v) const { return &attr[v * S]; }
    bool lit() const { return xMax >= xMin; }
};

/// The instance's mesh at wavelength w: every in.decimation-th vertex of the ghost's grid, its
/// attributes interpolated between the table's angles (Catmull-Rom) or, for a two-dimensional table,
/// its fields (bicubic), placed as `placement` says in the frame's pixels, the iris's blades evaluated
/// at its stop hits, and each vertex's Jacobian.
MeshVertices placeMesh(const ShapedTable& table, const MeshInstance& in, std::size_t w, const Placement& placement,
                       const trace::ImageFrame& frame);

} // namespace ff::ghosts
