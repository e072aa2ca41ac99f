#pragma once
// The Fourier evaluation on the GPU: the two separable passes of shaders/evaluate_rows.comp and
// shaders/evaluate_pixels.comp, the same products as the CPU's matrix form (fourier/evaluate.h) in
// float32.

#include "fourier/aggregate.h"
#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <memory>

namespace ff::gpu {

class GlEvaluator {
  public:
    explicit GlEvaluator(const GlContext& context);
    ~GlEvaluator();

    /// Overwrites image (its size is the frame's) with the series of z.
    void evaluate(const fourier::Coefficients& z, fourier::FlareImage& image);
    /// Adds the series of z (float [3][2n][2m] on the GPU; periods in pixels) to image (float
    /// [3][height][width] on the GPU).
    void add(const Buffer& z, int n, int m, double periodX, double periodY, int width, int height, Buffer& image);

  private:
    std::unique_ptr<ComputeProgram> rows_, pixels_;
    Buffer z_, basisX_, basisY_, t_, image_;
};

} // namespace ff::gpu
