#pragma once
// Checks shared by every lens reader (native, Zemax, pbrt) once a Lens is assembled: exactly one
// stop, a usable aperture, a positive image distance, consistent zoom data. Structural problems
// throw ff::Error (Input); tolerated quirks are reported as notes. Also resolves an 'auto' image
// distance.

#include "core/reporter.h"
#include "optics/lens.h"

namespace ff::optics {

/// `section` locates the surface list (used when no single surface is to blame).
void validateLens(Lens& lens, const SourceLocation& section, Reporter& reporter);

} // namespace ff::optics
