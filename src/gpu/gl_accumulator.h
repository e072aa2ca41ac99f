#pragma once
// The accumulation of the Fourier coefficients on the GPU (shaders/accumulate.comp): every ghost that
// the plan routes through the series, over all N x M terms (the CPU trims each ghost to its own
// terms; the GPU does not need to). Closed forms without erf: the periodised Gaussian and cos^2.

#include "fourier/aggregate.h"
#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <memory>

namespace ff::gpu {

class GlAccumulator {
  public:
    explicit GlAccumulator(const GlContext& context);
    ~GlAccumulator();

    /// Z of the plan's Fourier ghosts, read back in double. Throws ff::Error (Usage) for a Gaussian form
    /// other than periodised (the GPU has no erf; the A&S form would be the way to add one).
    fourier::Coefficients accumulate(const std::vector<fourier::Ghost>& ghosts, const fourier::Plan& plan,
                                     const fourier::FourierSettings& settings);
    /// The same into z, left on the GPU: float [3][2N][2M].
    void accumulate(const std::vector<fourier::Ghost>& ghosts, const fourier::Plan& plan,
                    const fourier::FourierSettings& settings, Buffer& z);

  private:
    std::unique_ptr<ComputeProgram> program_;
    Buffer ghosts_, z_;
    int localSize_ = 0;
};

} // namespace ff::gpu
