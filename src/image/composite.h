#pragma once
// Compositing the flare onto the plate: composite = plate + flare per colour channel, one float32
// addition per value (the GL backend's composite.comp computes the same bits). Where the flare is
// exactly zero, or the plate is NaN, the plate's value is kept as it is — NaN payloads, -0 and
// subnormals included — so a frame without flare composites to the plate itself.

#include <vector>

namespace ff::image {

/// plate and flare: R, G, B interleaved, the same size. Throws ff::Error (Runtime) if they differ.
std::vector<float> composite(const std::vector<float>& plate, const std::vector<float>& flare);

} // namespace ff::image
