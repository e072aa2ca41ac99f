#pragma once
// One ghost's mesh cut into the polygons it is drawn as (internal to ff_ghosts): shared by the
// renderer (shaped_render.cpp) and the fits derived from the table (shaped_fits.cpp).

#include "ghosts/polygons.h"
#include "ghosts/shaped_ghosts.h"

namespace ff::ghosts {

/// Cuts the ghost's mesh at wavelength w into clipped polygons in `frame`'s pixels, appended to `out`:
/// placed as `placement` says, every polygon's energy scaled by `flux`, cells subdivided as
/// ShapedRenderSettings says.
void meshPolygons(const ShapedTable& table, const MeshInstance& in, std::size_t w, const Placement& placement,
                  double flux, const trace::ImageFrame& frame, const ShapedRenderSettings& settings,
                  ShapedPolygons& out);

} // namespace ff::ghosts
