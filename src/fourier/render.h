#pragma once
// The aggregator end to end: plan, accumulate, evaluate, and draw the hybrid's direct ghosts.

#include "fourier/evaluate.h"

namespace ff::fourier {

struct StageSeconds {
    double plan = 0.0, accumulate = 0.0, evaluate = 0.0, direct = 0.0;
    double total() const { return plan + accumulate + evaluate + direct; }
};

struct FourierRender {
    FlareImage image;
    Plan plan;
    StageSeconds seconds;
};

/// The ghosts through the separable Fourier representation (hybrid per the settings).
FourierRender renderFourier(const std::vector<Ghost>& ghosts, int width, int height, const FourierSettings& settings);

/// Every ghost drawn directly (the `fitted` mode: the same profiles, no truncation).
FlareImage renderDirect(const std::vector<Ghost>& ghosts, int width, int height);

} // namespace ff::fourier
