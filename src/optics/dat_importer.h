#pragma once
// Importer for pbrt lens files (.dat): four numbers per row, front to back: radius, thickness,
// eta (index after the surface; 0 = air) and aperture *diameter*; radius 0 is the aperture stop.
// Files that store the axial position instead of the thickness are detected (the column grows
// monotonically) and converted, with a note saying which reading was used. A last thickness of 0
// (pbrt focuses separately) places the sensor at the paraxial focus.

#include "core/reporter.h"
#include "optics/lens.h"

#include <string>
#include <string_view>

namespace ff::optics {

Lens importDat(std::string_view text, const std::string& fileName, Reporter* reporter = nullptr);

} // namespace ff::optics
