#pragma once
// One ghost's mesh cut into the polygons it is drawn as (internal to ff_ghosts): shared by the
// renderer (shaped_render.cpp) and the fits derived from the table (shaped_fits.cpp).

#include "ghosts/polygons.h"
#include "ghosts/shaped_ghosts.h"

#include <limits>

namespace ff::ghosts {

/// A ghost between two of the table's angles: a0 and a0 + 1, at fraction t. In a two-dimensional
/// table (ShapedTable::FieldGrid), between its fields (a0, b0) and (a0 + 1, b0 + 1) of the grid's x
/// and y, at fractions t and s.
struct MeshInstance {
    std::size_t ghost = 0;
    int a0 = 0;
    double t = 0.0;
    double flatnessPx = 0.0; ///< the subdivision's tolerance (ShapedRenderSettings::flatnessPx)
    /// the tolerance where an aperture's edge crosses a cell (0: flatnessPx)
    double edgeFlatnessPx = 0.0;
    /// the largest error the elements' density may leave in a pixel, relative to the instance's
    /// brightest pixel (ShapedRenderSettings::irradianceError; infinity: none)
    double irradianceError = std::numeric_limits<double>::infinity();
    /// Every decimation-th vertex of the mesh on each axis (a divisor of the ghost's grid): cells
    /// of decimation^2 cells, for a grid coarser than the mesh (ShapedRenderSettings::grid).
    int decimation = 1;
    int b0 = 0;
    double s = 0.0;
};

/// Where a light puts the table's ghosts: their landing points turned by azimuthRad, then mirrored
/// (x times mirrorX, y times mirrorY, each +-1), and the iris seen from the table's frame the
/// inverse way (a light in another quadrant of a two-dimensional table is the mirror image of one
/// in the table's).
struct Placement {
    double azimuthRad = 0.0;
    double mirrorX = 1.0, mirrorY = 1.0;
};

/// Cuts the ghost's mesh at wavelength w into clipped polygons in `frame`'s pixels, appended to `out`:
/// placed as `placement` says, every polygon's energy scaled by `flux`, cells subdivided as
/// ShapedRenderSettings says.
void meshPolygons(const ShapedTable& table, const MeshInstance& in, std::size_t w, const Placement& placement,
                  double flux, const trace::ImageFrame& frame, const ShapedRenderSettings& settings,
                  ShapedPolygons& out);

} // namespace ff::ghosts
