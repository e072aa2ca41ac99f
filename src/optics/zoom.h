#pragma once
// A zoom lens at one of its positions: its gaps set, and an `auto` image distance refocused there.

#include "optics/lens.h"

#include <string>

namespace ff::optics {

/// The lens at zoom position k (thicknesses of that position; an 'auto' image distance refocused).
/// Throws ff::Error (Usage) when k is out of range.
Lens atZoom(const Lens& lens, std::size_t k);

/// Finds a zoom position by its label or 1-based index ("135", "2"); throws with the valid labels.
std::size_t findZoomPosition(const Lens& lens, const std::string& labelOrIndex);

} // namespace ff::optics
