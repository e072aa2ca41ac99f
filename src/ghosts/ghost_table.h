#pragma once
// The ghost table of a lens: every two-bounce ghost fitted (ghost_fit.h) per wavelength over field
// angles 0..thetaMax, so that a light anywhere in the frame costs a lookup, not a trace.
//
// Every ghost starts on 9 uniform field angles and then refines its own: the builder measures, for
// each of a ghost's intervals, the error of linear interpolation at its mid-angle against a direct
// trace (centroid relative to max(|centroid|, sigma, 1 % of the sensor half-height), sigma relative to
// itself, at wavelengths where the ghost carries at least 1 % of the strongest ghost's flux there)
// and keeps the mid-angle as a new entry of that ghost; only intervals above the tolerance are split
// further, so a ghost's angles gather where it changes fast (its vignetting onsets), until every
// interval passes, reaches the finest step (1/131072 of the field) or the budget (maxAngles traces per
// ghost on average) is spent; when the budget cannot take every failing interval, those with the
// largest error x width go first, whichever ghost they belong to. A mid-angle's pupil search looks
// where its neighbours' searches found light; where it finds light that a neighbour's search lacks
// and looking there finds it, the neighbour is traced again (its other interval then measured again),
// so that a piece of light one search stepped over is not lost between angles where another met it. The measured errors
// (median, 95th percentile, worst over the final intervals of ghosts that counted there) are stored with the table; an
// interval whose halves could not be measured counts with its own error.
//
// Each entry counts the light landing within twice the sensor's half-diagonal of the axis (grazing
// rays that land metres away can never reach the frame and would dominate the moments).
// Geometry follows the tracer: the source at azimuth 0, its direct image at +y; a ghost's centre is
// m x (direct image position), m = ghost centroid y / direct centroid y. Lengths in mm on the sensor,
// flux relative to the direct image at the same wavelength.

#include "ghosts/table_data.h"
#include "optics/lens.h"

#include <functional>
#include <string>
#include <vector>

namespace ff::ghosts {

/// Builds the table (parallel over ghosts x angles). Throws ff::Error (Input) for an anamorphic lens.
GhostTable buildGhostTable(const optics::Lens& lens, const TableSettings& settings, const Progress& progress = {});

/// What the table would hold at each of the given field angles, traced directly as the builder
/// traces its entries: [angle][ghost][wavelength], ghosts in the table's order, or only those whose
/// labels are given, in that order (an unknown label is an error). For checking a table's
/// interpolation against direct traces.
std::vector<std::vector<std::vector<TableEntry>>> traceEntries(const optics::Lens& lens, const TableSettings& settings,
                                                               const std::vector<double>& anglesDeg,
                                                               const std::vector<std::string>& onlyGhosts = {});

} // namespace ff::ghosts
