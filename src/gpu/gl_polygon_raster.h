#pragma once
// The shaped ghosts' polygons drawn on the GPU with the exact pixel-area coverage of the CPU's
// trace::CoverageRaster: shaders/polygon_edges.comp adds each polygon's edges to 64-bit fixed-point
// row entries with integer atomics, shaders/polygon_rows.comp takes each row's prefix sum. Integer
// sums do not depend on the order of the additions: the image has the same bytes on any run.

#include "ghosts/shaped_ghosts.h"
#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace ff::gpu {

class GlPolygonRaster final : public ghosts::PolygonRaster {
  public:
    /// Vertices held on the host before a batch is sent to the GPU (8 bytes each).
    static constexpr std::size_t kDefaultBatch = std::size_t(1) << 22;

    explicit GlPolygonRaster(const GlContext& context, std::size_t batch = kDefaultBatch);
    ~GlPolygonRaster() override;

    void begin(const trace::ImageFrame& frame, std::size_t channels, double energyBound) override;
    void draw(std::size_t c, const ghosts::ShapedPolygons& polygons) override;
    std::vector<std::vector<double>> finish() override;

  private:
    // std430 layout of polygon_edges.comp's Polygon.
    struct GpuPolygon {
        std::uint32_t first, count, channel, pad;
        double energy, gx, gy;
    };
    void flush();

    std::unique_ptr<ComputeProgram> edges_, rows_;
    Buffer vertices_, polygons_, accumulator_, image_;
    std::vector<glm::vec2> stagedVertices_;
    std::vector<GpuPolygon> stagedPolygons_;
    std::size_t batch_;
    int width_ = 0, height_ = 0;
    std::size_t channels_ = 0;
    double scale_ = 1.0;
};

} // namespace ff::gpu
