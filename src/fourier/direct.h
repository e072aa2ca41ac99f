#pragma once
// Drawing ghosts directly: each separable profile integrated exactly over every pixel of its
// footprint (the part of the frame within its extent). The reference the Fourier path is tested
// against, the `fitted` rendering mode, and the hybrid path's renderer for ghosts too small for the
// chosen number of terms.

#include "fourier/ghost.h"

#include <cstddef>
#include <vector>

namespace ff::fourier {

/// Integral of the unit-peak profile over [a, b] (the profile centred at 0).
double profileIntegral(Shape s, double width, double a, double b);

/// Adds the ghosts `which` (indices into ghosts) to image. Deterministic for any thread count (rows
/// in parallel, ghosts in the given order within a row).
void drawDirect(const std::vector<Ghost>& ghosts, const std::vector<std::size_t>& which, FlareImage& image);
/// Adds every ghost.
void drawDirect(const std::vector<Ghost>& ghosts, FlareImage& image);

} // namespace ff::fourier
