#pragma once
// The hybrid path's direct drawing on the GPU (shaders/direct_draw.comp): ghosts too small for the
// series integrated over every pixel of their footprint, as fourier::drawDirect does on the CPU.

#include "fourier/ghost.h"
#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace ff::gpu {

class GlDirect {
public:
    explicit GlDirect(const GlContext& context);
    ~GlDirect();

    /// Adds the ghosts `which` to image (float [3][height][width] on the GPU).
    void add(const std::vector<fourier::Ghost>& ghosts, const std::vector<std::size_t>& which, int width, int height, Buffer& image);
    /// Adds them to a CPU image (uploaded, drawn into, read back).
    void draw(const std::vector<fourier::Ghost>& ghosts, const std::vector<std::size_t>& which, fourier::FlareImage& image);

private:
    std::unique_ptr<ComputeProgram> program_;
    Buffer ghosts_, image_;
};

} // namespace ff::gpu
