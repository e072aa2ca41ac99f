#pragma once
// One ghost's mesh cut into the polygons it is drawn as (internal to ff_ghosts): shared by the
// renderer (shaped_render.cpp) and the fits derived from the table (shaped_fits.cpp).

#include "ghosts/polygons.h"
#include "ghosts/shaped_ghosts.h"

#include <limits>

namespace ff::ghosts {

/// A ghost between two of the table's angles: a0 and a0 + 1, at fraction t.
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
};

/// Cuts the ghost's mesh at wavelength w into clipped polygons in `frame`'s pixels, appended to `out`:
/// its landing points turned by azimuthRad (the iris by -azimuthRad in the table's frame), every
/// polygon's energy scaled by `flux`, cells subdivided as ShapedRenderSettings says.
void meshPolygons(const ShapedTable& table, const MeshInstance& in, std::size_t w, double azimuthRad, double flux,
                  const trace::ImageFrame& frame, const ShapedRenderSettings& settings, ShapedPolygons& out);

} // namespace ff::ghosts
