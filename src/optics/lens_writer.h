#pragma once
// Writes a Lens in the native `.lens` format (docs/lens-format.md). Reading the result back gives
// the same prescription (surfaces, media, apertures, coatings, zoom data, header).

#include "optics/lens.h"

#include <string>

namespace ff::optics {

std::string writeLensText(const Lens& lens);

} // namespace ff::optics
