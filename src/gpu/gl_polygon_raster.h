#pragma once
// The shaped ghosts' polygons drawn on the GPU with the exact pixel-area coverage of the CPU's
// trace::CoverageRaster, binned: shaders/polygon_bins.comp sorts each batch's polygons into lists per
// 16 x 16-pixel tile and channel (offsets by shaders/bin_scan.comp), shaders/polygon_tiles.comp draws
// each tile's list in shared memory (64-bit fixed point, integer atomics) and adds its pixels to the
// frame's sums once, shaders/polygon_image.comp reads them out. Integer sums do not depend on the
// order of the additions: the image has the same bytes on any run and for any batching. The shaped
// ghosts' meshes can be cut into those polygons on the GPU too (gl_mesh_cutter.h, drawMeshes).

#include "ghosts/shaped_ghosts.h"
#include "gpu/gl_context.h"
#include "gpu/gl_mesh_cutter.h"
#include "gpu/gl_objects.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace ff::gpu {

class GlPolygonRaster final : public ghosts::PolygonRaster {
  public:
    /// Vertices held on the host before a batch is sent to the GPU (8 bytes each).
    static constexpr std::size_t kDefaultBatch = std::size_t(1) << 22;
    /// A bound on a batch's (polygon, tile) pairs, the bins' lists (4 bytes each, 256 MiB at the
    /// default; their offsets are 32-bit): a batch is sent before its polygons' tile boxes could hold
    /// more (one polygon alone may: at most every tile of the frame).
    static constexpr std::size_t kDefaultListEntries = std::size_t(1) << 26;

    /// cutMeshes: take the shaped tables GlMeshCutter takes (cutsMeshes); false: renderShaped cuts
    /// every mesh on the CPU and sends the polygons.
    explicit GlPolygonRaster(const GlContext& context, std::size_t batch = kDefaultBatch,
                             std::size_t listEntries = kDefaultListEntries, bool cutMeshes = true);
    ~GlPolygonRaster() override;

    void begin(const trace::ImageFrame& frame, std::size_t channels, double energyBound) override;
    void draw(std::size_t c, const ghosts::ShapedPolygons& polygons) override;
    std::vector<std::vector<double>> finish() override;
    bool cutsMeshes(const ghosts::ShapedTable& table) const override;
    std::vector<ghosts::MeshDrawn> drawMeshes(const ghosts::ShapedTable& table,
                                              const std::vector<ghosts::MeshLight>& lights,
                                              const std::vector<ghosts::MeshDraw>& draws, std::size_t channels,
                                              const ghosts::ShapedRenderSettings& settings,
                                              float splatBelow = 0.0f) override;

  private:
    // std430 layout of polygon_bins.comp's Polygon.
    struct GpuPolygon {
        std::uint32_t first, count, channel, splat;
        double energy, gx, gy;
    };
    void flush();
    // Draws polygons[first .. first + count) of the polygons_ and vertices_ buffers into the sums.
    void rasterise(std::size_t first, std::size_t count);

    std::unique_ptr<ComputeProgram> bins_, scan_, tiles_, image_;
    // The batch (vertices, polygons, each polygon's kind, density and tiles), the bins' counts (then
    // cursors), offsets and lists, the frame's 64-bit sums and the image read back.
    Buffer vertices_, polygons_, prepared_, counts_, offsets_, lists_, accumulator_, pixels_;
    std::vector<glm::vec2> stagedVertices_;
    std::vector<GpuPolygon> stagedPolygons_;
    std::size_t batch_, listEntries_;
    bool cutMeshes_;
    std::unique_ptr<GlMeshCutter> cutter_;
    trace::ImageFrame frame_;
    std::size_t stagedEntries_ = 0; ///< the staged polygons' tile boxes, summed: a bound on their lists
    int width_ = 0, height_ = 0, tilesX_ = 0, tilesY_ = 0;
    std::size_t channels_ = 0;
    double scale_ = 1.0;
};

} // namespace ff::gpu
