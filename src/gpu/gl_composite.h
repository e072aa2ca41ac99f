#pragma once
// Compositing on the GPU (shaders/composite.comp): the plate as a texture plus the flare layer, bit
// for bit what image::composite computes on the CPU.

#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <memory>
#include <vector>

namespace ff::gpu {

class GlCompositor {
  public:
    explicit GlCompositor(const GlContext& context);
    ~GlCompositor();

    /// Largest plate side the device takes as a texture.
    int maxSide() const { return maxSide_; }
    /// plate: R, G, B interleaved (width x height); flare: float [3][height][width] on the GPU.
    /// Returns the composite, R, G, B interleaved. Throws ff::Error (Runtime) beyond maxSide().
    std::vector<float> composite(const std::vector<float>& plate, int width, int height, const Buffer& flare);

  private:
    std::unique_ptr<ComputeProgram> program_;
    Texture plate_;
    Buffer out_;
    int maxSide_ = 0;
};

} // namespace ff::gpu
