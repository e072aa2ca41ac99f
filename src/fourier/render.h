#pragma once
// The aggregator end to end: plan, accumulate, evaluate, and draw the hybrid's direct ghosts.

#include "fourier/backend.h"
#include "fourier/evaluate.h"

#include <optional>
#include <string>

namespace ff::fourier {

struct FourierRender {
    FlareImage image;
    Plan plan;                  ///< the frame's level
    std::optional<Plan> coarse; ///< the wide ghosts' level (indices into the wide ghosts, in order)
    StageSeconds seconds;

    /// Both levels in words.
    std::string describe() const;
    std::size_t fourierCount() const { return plan.fourier + (coarse ? coarse->fourier : 0); }
    std::size_t directCount() const { return plan.direct + (coarse ? coarse->direct : 0); }
    std::size_t culledCount() const { return plan.culled + (coarse ? coarse->culled : 0); }
};

/// The ghosts through the separable Fourier representation (hybrid per the settings). Ghosts too wide
/// for the frame's period (they would wrap into it) get a coarse level: a period of their own (up to
/// 32 times the frame), N by the budget; any still wider are drawn directly.
FourierRender renderFourier(const std::vector<Ghost>& ghosts, int width, int height, const FourierSettings& settings);

/// Every ghost drawn directly (the `fitted` mode: the same profiles, no truncation).
FlareImage renderDirect(const std::vector<Ghost>& ghosts, int width, int height);

} // namespace ff::fourier
