#pragma once
// Checks shared by every way a plate is made (plate.cpp reads files, plate_pixels.cpp takes pixels in
// memory): ff::Error (Input, naming `path`) for a plate that is not usable.

#include "image/plate.h"

#include <string>

namespace ff::image {

/// Finds R, G, B (or a luminance Y: a note) and A among the plate's channel names.
void findChannels(const std::string& path, Plate& p);
/// A plate with a majority of negative, NaN or infinite pixels is not image data.
void checkValues(const std::string& path, const Plate& p);

} // namespace ff::image
