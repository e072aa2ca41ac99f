#pragma once
// The fitted ghost table of a lens: every stored ghost of its shaped table (shaped_ghosts.h) measured
// and fitted (ghost_fit.h) per wavelength at the shaped table's field angles, so that a light
// anywhere in the frame costs a lookup, not a trace, and game engines get the profiles they import.
//
// Each entry comes from the ghost's mesh at that angle and wavelength, cut by the iris and the
// apertures exactly as the shaped renderer draws it: flux and moments exactly from the polygons
// (ghost_fit.h), the profiles fitted to them drawn into a local image. Between the table's angles
// entries are interpolated linearly, as the meshes are. Only light landing within twice the sensor's
// half-diagonal of the axis counts (grazing rays that land metres away can never reach the frame and
// would dominate the moments). Geometry follows the tracer: the source at azimuth 0, its direct image
// at +y; a ghost's centre is m x (direct image position), m = ghost centroid y / direct centroid y.
// Lengths in mm on the sensor, flux relative to the direct image at the same wavelength.

#include "ghosts/shaped_ghosts.h"
#include "ghosts/table_data.h"
#include "optics/lens.h"

namespace ff::ghosts {

/// The fits of every stored ghost of `table` at its angles and wavelengths (parallel over entries).
/// Progress counts entries. The lens gives the table's header (name, file, focal length, iris). A
/// two-dimensional table (an anamorphic lens's) gets the header only: no ghosts, no angles.
GhostTable fitShapedTable(const ShapedTable& table, const optics::Lens& lens, const Progress& progress = {});

/// The lens's table: its meshes traced (traceShapedTable) and its fits derived (fitShapedTable).
/// Progress counts the ghosts traced, then the fits. An anamorphic lens's table is two-dimensional
/// and has no fits.
ShapedTable buildShapedTable(const optics::Lens& lens, const TableSettings& settings, const Progress& progress = {});

/// buildShapedTable's fitted table.
GhostTable buildGhostTable(const optics::Lens& lens, const TableSettings& settings, const Progress& progress = {});

} // namespace ff::ghosts
