#pragma once
// What the aggregator returns (render.h and the Fourier-Bessel variant, bessel.h): the image, the
// plans of its levels and the stages' times.

#include "fourier/backend.h"
#include "fourier/evaluate.h"
#include "fourier/plan.h"

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

} // namespace ff::fourier
