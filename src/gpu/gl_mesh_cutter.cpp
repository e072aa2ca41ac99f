#include "gpu/gl_mesh_cutter.h"

#include "core/error.h"
#include "ghosts/mesh_clip.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace ff::gpu {

std::string_view embedded(std::string_view name);

namespace {

constexpr int kGroup = 64;                             // mesh_place.comp, mesh_cells.comp
constexpr int kScanGroup = 256;                        // bin_scan.comp
constexpr std::size_t kJobBytes = 80 + 2 * kGroup * 4; // their Job (std430)
constexpr std::size_t kPolygonBytes = 40;              // polygon_bins.comp's Polygon
// Per batch, within the device's storage block size (128 MiB on llvmpipe): the jobs' vertices, and
// the polygons or the vertices they make. Fewer batches, fewer passes of the raster over the tiles.
constexpr std::size_t kScratchBytes = std::size_t(1) << 30;
constexpr std::size_t kOutputBytes = std::size_t(1) << 30;
constexpr std::uint32_t kNoMesh = 0xffffffffu;

// std430 layout of the shaders' Instance.
struct GpuInstance {
    std::uint32_t ghost, light;
    std::int32_t a0, decimation;
    double t, flatnessPx, edgeFlatnessPx, irradianceError;
};
static_assert(sizeof(GpuInstance) == 48);

std::size_t blockLimit() {
    GLint64 bytes = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &bytes);
    return static_cast<std::size_t>(std::max<GLint64>(bytes, 0));
}

// The iris's edges as the shaders count them: its blades, or 1 for a circle.
int irisEdges(const trace::Iris& iris) {
    return iris.blades >= 3 ? iris.blades : 1;
}

// Doubles per vertex of a ghost's mesh in the shaders' scratch.
std::size_t vertexDoubles(const ghosts::ShapedGhost& g, int edges) {
    return 4 + std::min(ghosts::kMaxConstraints, g.apertureSteps.size() + g.stopCrossings * std::size_t(edges));
}

std::size_t tableFloats(const ghosts::ShapedTable& table, std::size_t channels) {
    std::size_t floats = 0;
    for (const auto& g : table.ghosts)
        for (std::size_t w = 0; w < channels && w < g.meshes.size(); ++w)
            for (const auto& m : g.meshes[w]) floats += m.data.size();
    return floats;
}

std::string keyOf(const ghosts::ShapedTable& table, std::size_t channels) {
    return std::to_string(reinterpret_cast<std::uintptr_t>(&table)) + " " + table.lensHash + " " +
           std::to_string(table.rays) + " " + std::to_string(table.ghosts.size()) + " " +
           std::to_string(table.angles()) + " " + std::to_string(table.buildSeconds) + " " + std::to_string(channels);
}

} // namespace

GlMeshCutter::GlMeshCutter() {
    place_ = std::make_unique<ComputeProgram>("mesh_place.comp", embedded("mesh_place.comp"), kGroup);
    cells_ = std::make_unique<ComputeProgram>("mesh_cells.comp", embedded("mesh_cells.comp"), kGroup);
    scan_ = std::make_unique<ComputeProgram>("bin_scan.comp", embedded("bin_scan.comp"), kScanGroup);
}

GlMeshCutter::~GlMeshCutter() = default;

bool GlMeshCutter::takes(const ghosts::ShapedTable& table) {
    if (table.twoDimensional() || table.ghosts.empty() || table.angles() < 1) return false;
    const std::size_t limit = blockLimit();
    const std::size_t channels = std::min<std::size_t>(3, table.wavelengthsNm.size());
    if (tableFloats(table, channels) * sizeof(float) > limit) return false;
    for (const auto& g : table.ghosts) {
        const std::size_t vertices = static_cast<std::size_t>(g.grid + 1) * (g.grid + 1);
        if (vertices * vertexDoubles(g, irisEdges(table.iris)) * sizeof(double) > std::min(limit, kScratchBytes))
            return false;
    }
    return true;
}

void GlMeshCutter::upload(const ghosts::ShapedTable& table, std::size_t channels) {
    const std::string key = keyOf(table, channels);
    if (key == tableKey_) return;
    const std::size_t A = static_cast<std::size_t>(table.angles());
    std::vector<float> data;
    data.reserve(tableFloats(table, channels));
    std::vector<std::uint32_t> index;
    for (const auto& g : table.ghosts)
        index.insert(index.end(),
                     {static_cast<std::uint32_t>(g.grid), static_cast<std::uint32_t>(g.stride()),
                      static_cast<std::uint32_t>(g.apertureSteps.size()), static_cast<std::uint32_t>(g.stopCrossings)});
    for (const auto& g : table.ghosts)
        for (std::size_t w = 0; w < channels; ++w)
            for (std::size_t a = 0; a < A; ++a) {
                const ghosts::ShapedMesh& m = g.meshes.at(w).at(a);
                if (m.data.empty()) {
                    index.push_back(kNoMesh);
                    continue;
                }
                if (m.data.size() != static_cast<std::size_t>(g.grid + 1) * (g.grid + 1) * g.stride())
                    throw Error(ErrorKind::Runtime, "a shaped ghost's mesh does not match its grid");
                index.push_back(static_cast<std::uint32_t>(data.size()));
                data.insert(data.end(), m.data.begin(), m.data.end());
            }
    table_.upload(data.data(), std::max<std::size_t>(data.size(), 1) * sizeof(float));
    index_.upload(index.data(), index.size() * sizeof(std::uint32_t));
    tableKey_ = key;
}

std::size_t GlMeshCutter::uploadFrame(const ghosts::ShapedTable& table, const std::vector<ghosts::MeshLight>& lights,
                                      const std::vector<ghosts::MeshDraw>& draws) {
    // The lights: (cos, sin) of the azimuth, the mirrors, the flux, then the iris's blade normals
    // turned by -azimuth and mirrored (ghosts::meshPolygons' IrisEdges).
    const trace::Iris& iris = table.iris;
    const int edges = irisEdges(iris);
    const double sector = 2.0 * std::numbers::pi / std::max(iris.blades, 1);
    std::vector<double> light;
    light.reserve(lights.size() * (8 + 2 * edges));
    for (const auto& l : lights) {
        const auto& p = l.placement;
        light.insert(light.end(), {std::cos(p.azimuthRad), std::sin(p.azimuthRad), p.mirrorX, p.mirrorY, l.flux[0],
                                   l.flux[1], l.flux[2], 0.0});
        for (int k = 0; k < edges && edges > 1; ++k) {
            const double phi = iris.rotationRad - p.azimuthRad + (k + 0.5) * sector;
            light.insert(light.end(), {p.mirrorX * std::cos(phi), p.mirrorY * std::sin(phi)});
        }
    }
    lights_.upload(light.data(), std::max<std::size_t>(light.size(), 1) * sizeof(double));
    // The instances, and the largest mesh among them (doubles in the scratch).
    std::vector<GpuInstance> instances;
    instances.reserve(draws.size());
    std::size_t slot = 1;
    for (const auto& d : draws) {
        const auto& m = d.mesh;
        if (d.light >= lights.size() || m.ghost >= table.ghosts.size())
            throw Error(ErrorKind::Runtime, "a ghost instance names no light or ghost of the table");
        instances.push_back({static_cast<std::uint32_t>(m.ghost), static_cast<std::uint32_t>(d.light), m.a0,
                             m.decimation, m.t, m.flatnessPx, m.edgeFlatnessPx, m.irradianceError});
        const ghosts::ShapedGhost& g = table.ghosts[m.ghost];
        const int n = g.grid / (m.decimation > 0 && g.grid % m.decimation == 0 ? m.decimation : 1);
        slot = std::max(slot, static_cast<std::size_t>(n + 1) * (n + 1) * vertexDoubles(g, edges));
    }
    instances_.upload(instances.data(), instances.size() * sizeof(GpuInstance));
    return slot;
}

std::array<std::uint32_t, 2> GlMeshCutter::count(const Batch& b, const ghosts::ShapedTable& table,
                                                 const ghosts::ShapedRenderSettings& settings, float splatBelow,
                                                 const trace::ImageFrame& frame) {
    const trace::Iris& iris = table.iris;
    const double apothem =
        iris.blades >= 3 ? iris.circumradius * std::cos(std::numbers::pi / iris.blades) : iris.radius;
    if (scratch_.bytes() < b.jobs * b.slot * sizeof(double)) scratch_.upload(nullptr, b.jobs * b.slot * sizeof(double));
    if (jobs_.bytes() < b.jobs * kJobBytes) jobs_.upload(nullptr, b.jobs * kJobBytes);
    if (counts_.bytes() < 2 * b.vertsAt * 4) {
        counts_.upload(nullptr, 2 * b.vertsAt * 4);
        offsets_.upload(nullptr, 2 * b.vertsAt * 4);
    }
    if (stats_.bytes() < b.jobs * 2 * sizeof(double)) stats_.upload(nullptr, b.jobs * 2 * sizeof(double));
    // Each job's mesh placed in the frame.
    table_.bind(0);
    index_.bind(1);
    instances_.bind(2);
    lights_.bind(3);
    scratch_.bind(4);
    jobs_.bind(5);
    place_->use();
    place_->set("jobFirst", static_cast<int>(b.first));
    place_->set("jobCount", static_cast<int>(b.jobs));
    place_->set("channels", static_cast<int>(b.channels));
    place_->set("angles", table.angles());
    place_->set("ghosts", static_cast<int>(table.ghosts.size()));
    place_->set("slot", static_cast<int>(b.slot));
    place_->set("blades", irisEdges(iris));
    place_->set("width", frame.width);
    place_->set("height", frame.height);
    place_->setDouble("pitch", frame.pitchMm);
    place_->setDouble("centreX", frame.centreXMm);
    place_->setDouble("centreY", frame.centreYMm);
    place_->setDouble("apothem", apothem);
    dispatchGroups(static_cast<GLuint>(b.jobs));
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    checkGl("mesh_place.comp");
    // Its cells counted; the jobs' polygons and vertices scanned.
    cells_->use();
    cells_->set("jobFirst", static_cast<int>(b.first));
    cells_->set("jobCount", static_cast<int>(b.jobs));
    cells_->set("channels", static_cast<int>(b.channels));
    cells_->set("slot", static_cast<int>(b.slot));
    cells_->set("blades", irisEdges(iris));
    cells_->set("vertsAt", static_cast<int>(b.vertsAt));
    cells_->set("width", frame.width);
    cells_->set("height", frame.height);
    cells_->set("maxSubdivision", std::max(settings.maxSubdivision, 1));
    cells_->set("linearDensity", settings.linearDensity ? 1 : 0);
    cells_->setDouble("subcellPx", settings.subcellPx);
    cells_->set("splatBelow", splatBelow);
    cells_->set("pass", 0);
    jobs_.bind(0); // no polygons written in pass 0
    jobs_.bind(3);
    counts_.bind(6);
    stats_.bind(7);
    dispatchGroups(static_cast<GLuint>(b.jobs));
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    scan_->use();
    scan_->set("n", static_cast<int>(b.jobs));
    for (std::size_t at : {std::size_t(0), b.vertsAt}) {
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 5, counts_.id(), static_cast<GLintptr>(at * 4),
                          static_cast<GLsizeiptr>(b.jobs * 4));
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 7, offsets_.id(), static_cast<GLintptr>(at * 4),
                          static_cast<GLsizeiptr>((b.jobs + 1) * 4));
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("mesh_cells.comp (counting), bin_scan.comp");
    std::array<std::uint32_t, 2> totals{};
    glGetNamedBufferSubData(offsets_.id(), static_cast<GLintptr>(b.jobs * 4), 4, &totals[0]);
    glGetNamedBufferSubData(offsets_.id(), static_cast<GLintptr>((b.vertsAt + b.jobs) * 4), 4, &totals[1]);
    return totals;
}

void GlMeshCutter::write(const Batch& b, Buffer& vertices, Buffer& polygons, std::vector<ghosts::MeshDrawn>& out) {
    // The counted polygons written (cells_ keeps the uniforms count set).
    index_.bind(1);
    instances_.bind(2);
    scratch_.bind(4);
    jobs_.bind(5);
    vertices.bind(0);
    polygons.bind(3);
    offsets_.bind(6);
    stats_.bind(7);
    cells_->use();
    cells_->set("pass", 1);
    dispatchGroups(static_cast<GLuint>(b.jobs));
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("mesh_cells.comp");
    std::vector<double> stats(2 * b.jobs);
    std::vector<std::uint32_t> offsets(b.jobs + 1);
    stats_.download(stats.data(), stats.size() * sizeof(double));
    offsets_.download(offsets.data(), offsets.size() * sizeof(std::uint32_t));
    for (std::size_t j = 0; j < b.jobs; ++j)
        out[b.first + j] = {stats[2 * j], stats[2 * j + 1], static_cast<std::size_t>(offsets[j + 1] - offsets[j])};
}

std::vector<ghosts::MeshDrawn> GlMeshCutter::cut(const ghosts::ShapedTable& table,
                                                 const std::vector<ghosts::MeshLight>& lights,
                                                 const std::vector<ghosts::MeshDraw>& draws, std::size_t channels,
                                                 const ghosts::ShapedRenderSettings& settings, float splatBelow,
                                                 const trace::ImageFrame& frame, Buffer& vertices, Buffer& polygons,
                                                 const std::function<void(std::size_t)>& draw) {
    const std::size_t jobs = draws.size() * channels;
    std::vector<ghosts::MeshDrawn> out(jobs);
    if (jobs == 0) return out;
    upload(table, channels);
    const std::size_t slot = uploadFrame(table, lights, draws);
    GLint align = 4;
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &align);
    const std::size_t alignWords = std::max<std::size_t>(1, static_cast<std::size_t>(std::max(align, 4)) / 4);
    const std::size_t limit = blockLimit();
    const std::size_t outputLimit = std::min(limit, kOutputBytes);
    // Batches of jobs whose meshes fit the scratch; halved where their polygons would not fit a buffer.
    std::size_t batch = std::max<std::size_t>(1, std::min(limit, kScratchBytes) / (slot * sizeof(double)));
    for (std::size_t j0 = 0; j0 < jobs;) {
        Batch b{j0, std::min(batch, jobs - j0), channels, slot, 0};
        b.vertsAt = (b.jobs + 1 + alignWords - 1) / alignWords * alignWords;
        const auto [polys, verts] = count(b, table, settings, splatBelow, frame);
        if ((polys * kPolygonBytes > outputLimit || verts * sizeof(float) * 2 > outputLimit) && b.jobs > 1) {
            batch = b.jobs / 2;
            continue;
        }
        if (polygons.bytes() < std::max<std::size_t>(polys, 1) * kPolygonBytes)
            polygons.upload(nullptr, std::max<std::size_t>(polys, 1) * kPolygonBytes);
        if (vertices.bytes() < std::max<std::size_t>(verts, 1) * 2 * sizeof(float))
            vertices.upload(nullptr, std::max<std::size_t>(verts, 1) * 2 * sizeof(float));
        write(b, vertices, polygons, out);
        if (polys > 0) draw(polys);
        j0 += b.jobs;
    }
    return out;
}

} // namespace ff::gpu
