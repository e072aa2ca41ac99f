#pragma once
// Coefficients of sampled profiles on the GPU (shaders/sampled_coefficients.comp, then
// shaders/sum_coefficients.comp): the GPU twin of fourier::accumulateSampled.

#include "fourier/sampled.h"
#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <memory>

namespace ff::gpu {

class GlSampled {
  public:
    explicit GlSampled(const GlContext& context);
    ~GlSampled();

    /// Adds the ghosts' coefficients to z (float [3][2n][2m] on the GPU).
    void add(const std::vector<fourier::SampledGhost>& ghosts, int n, int m, double periodX, double periodY, Buffer& z);
    /// Adds them to z on the CPU (uploaded, added to, read back).
    void accumulate(const std::vector<fourier::SampledGhost>& ghosts, fourier::Coefficients& z);

  private:
    std::unique_ptr<ComputeProgram> terms_, sum_;
    Buffer ghosts_, values_, slices_, z_;
};

} // namespace ff::gpu
