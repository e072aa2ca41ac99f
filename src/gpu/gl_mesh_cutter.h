#pragma once
// The shaped ghosts' meshes cut into polygons on the GPU, as ghosts::meshPolygons cuts them on the CPU
// (shaped_mesh.cpp): the table's meshes uploaded once per table, then per frame only the lights
// (placement, flux, the iris turned with them) and the instances (ghost, table angle, tolerances:
// 48 bytes each). shaders/mesh_place.comp interpolates each instance's mesh between the table's
// angles and places it in the frame, shaders/mesh_cells.comp subdivides and clips its cells, counting
// first and then writing the polygons at offsets bin_scan.comp gives, in the layout the binned raster
// reads (gl_polygon_raster.h). Tables over one field angle (rotationally symmetric lenses); an
// anamorphic lens's two-dimensional table is cut on the CPU.

#include "ghosts/shaped_ghosts.h"
#include "gpu/gl_objects.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ff::gpu {

class GlMeshCutter {
  public:
    GlMeshCutter();
    ~GlMeshCutter();

    /// Whether the cutter takes the table: one field angle, at most the shaders' constraints per
    /// ghost, and meshes that fit one shader storage block of this context.
    static bool takes(const ghosts::ShapedTable& table);

    /// Cuts every instance's mesh at wavelengths 0 .. channels - 1 (channel w; polygons narrower than
    /// splatBelow pixels on both axes marked to be splatted), writing batches of
    /// polygons into `vertices` and `polygons` (polygon_bins.comp's layout) and calling draw(count)
    /// after each; per instance and channel, instance-major, the energy, area and polygons made.
    std::vector<ghosts::MeshDrawn> cut(const ghosts::ShapedTable& table, const std::vector<ghosts::MeshLight>& lights,
                                       const std::vector<ghosts::MeshDraw>& draws, std::size_t channels,
                                       const ghosts::ShapedRenderSettings& settings, float splatBelow,
                                       const trace::ImageFrame& frame, Buffer& vertices, Buffer& polygons,
                                       const std::function<void(std::size_t)>& draw);

  private:
    // Jobs first .. first + jobs - 1 (an instance's channels are consecutive jobs).
    struct Batch {
        std::size_t first = 0, jobs = 0, channels = 0;
        std::size_t slot = 0;    ///< doubles of scratch per job
        std::size_t vertsAt = 0; ///< where the vertex counts start in counts_ and offsets_ (uint32s)
    };
    void upload(const ghosts::ShapedTable& table, std::size_t channels);
    // The frame's lights and instances sent; the scratch a job needs (doubles).
    std::size_t uploadFrame(const ghosts::ShapedTable& table, const std::vector<ghosts::MeshLight>& lights,
                            const std::vector<ghosts::MeshDraw>& draws);
    // The batch's meshes placed and their cells counted: its polygons and vertices.
    std::array<std::uint32_t, 2> count(const Batch& b, const ghosts::ShapedTable& table,
                                       const ghosts::ShapedRenderSettings& settings, float splatBelow,
                                       const trace::ImageFrame& frame);
    // The counted polygons written; each job's energy, area and polygons into out.
    void write(const Batch& b, Buffer& vertices, Buffer& polygons, std::vector<ghosts::MeshDrawn>& out);

    std::unique_ptr<ComputeProgram> place_, cells_, scan_;
    // The table (its meshes, then per ghost its layout and per mesh its first float), the frame's
    // instances and lights, each job's vertices (doubles), state, counts and offsets, energy and area.
    Buffer table_, index_, instances_, lights_, scratch_, jobs_, counts_, offsets_, stats_;
    std::string tableKey_; ///< the table uploaded (its identity and the channels)
};

} // namespace ff::gpu
