#pragma once
// The aggregator end to end: plan, accumulate, evaluate, and draw the hybrid's direct ghosts.

#include "fourier/backend.h"
#include "fourier/render_result.h"

namespace ff::fourier {

/// The ghosts through the separable Fourier representation (hybrid per the settings). Ghosts too wide
/// for the frame's period (they would wrap into it) get a coarse level: a period of their own (up to
/// 32 times the frame), N by the budget; any still wider are drawn directly.
FourierRender renderFourier(const std::vector<Ghost>& ghosts, int width, int height, const FourierSettings& settings);

/// Every ghost drawn directly (the `fitted` mode: the same profiles, no truncation).
FlareImage renderDirect(const std::vector<Ghost>& ghosts, int width, int height);

} // namespace ff::fourier
