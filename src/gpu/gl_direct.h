#pragma once
// The hybrid path's direct drawing on the GPU: ghosts too small for the series integrated over every
// pixel of their footprint, as fourier::drawDirect does on the CPU — each ghost's per-pixel integrals
// along x and y once (shaders/direct_axes.comp), then their products per pixel, each 16 x 16 tile
// visiting the ghosts the host binned to it (shaders/direct_draw.comp).

#include "fourier/ghost.h"
#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace ff::gpu {

class GlDirect {
  public:
    /// Axis integrals (vec4) and tile-list entries per batch of ghosts: at most 64 MiB of integrals;
    /// more ghosts are drawn in several batches.
    static constexpr std::size_t kDefaultBatch = std::size_t(1) << 22;

    explicit GlDirect(const GlContext& context, std::size_t batch = kDefaultBatch);
    ~GlDirect();

    /// Adds the ghosts `which` to image (float [3][height][width] on the GPU).
    void add(const std::vector<fourier::Ghost>& ghosts, const std::vector<std::size_t>& which, int width, int height,
             Buffer& image);
    /// Adds them to a CPU image (uploaded, drawn into, read back).
    void draw(const std::vector<fourier::Ghost>& ghosts, const std::vector<std::size_t>& which,
              fourier::FlareImage& image);

  private:
    std::unique_ptr<ComputeProgram> program_, axes_;
    Buffer ghosts_, integrals_, tileStart_, tileGhosts_, image_;
    std::size_t batch_;
};

} // namespace ff::gpu
