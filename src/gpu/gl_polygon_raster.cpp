#include "gpu/gl_polygon_raster.h"

#include "core/error.h"

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

namespace ff::gpu {

std::string_view embedded(std::string_view name);

namespace {

constexpr int kGroup = 64;            // invocations per work group of the bins, tiles and image passes
constexpr int kScanGroup = 256;       // bin_scan.comp's one work group
constexpr int kTile = 16;             // pixels per side of a tile (polygon_bins.comp, polygon_tiles.comp)
constexpr std::size_t kPrepared = 64; // bytes per polygon of polygon_bins.comp's Prepared

} // namespace

GlPolygonRaster::GlPolygonRaster(const GlContext&, std::size_t batch, std::size_t listEntries, bool cutMeshes)
    : batch_(std::max<std::size_t>(batch, 64)), listEntries_(std::max<std::size_t>(listEntries, 1)),
      cutMeshes_(cutMeshes) {
    bins_ = std::make_unique<ComputeProgram>("polygon_bins.comp", embedded("polygon_bins.comp"), kGroup);
    scan_ = std::make_unique<ComputeProgram>("bin_scan.comp", embedded("bin_scan.comp"), kScanGroup);
    tiles_ = std::make_unique<ComputeProgram>("polygon_tiles.comp", embedded("polygon_tiles.comp"), kGroup);
    image_ = std::make_unique<ComputeProgram>("polygon_image.comp", embedded("polygon_image.comp"), kGroup);
}

GlPolygonRaster::~GlPolygonRaster() = default;

void GlPolygonRaster::begin(const trace::ImageFrame& frame, std::size_t channels, double energyBound) {
    if (!(energyBound > 0.0) || !std::isfinite(energyBound))
        throw Error(ErrorKind::Runtime, "the GL polygon raster needs a positive, finite energy bound");
    frame_ = frame;
    width_ = std::max(frame.width, 0);
    height_ = std::max(frame.height, 0);
    tilesX_ = (width_ + kTile - 1) / kTile;
    tilesY_ = (height_ + kTile - 1) / kTile;
    channels_ = channels;
    // Every pixel's sum stays below 2^62 units: one pixel holds at most energyBound.
    scale_ = std::ldexp(1.0, 62) / energyBound;
    stagedVertices_.clear();
    stagedPolygons_.clear();
    stagedEntries_ = 0;
    accumulator_.zeros(std::max<std::size_t>(1, channels_ * height_ * width_ * 2 * sizeof(std::uint32_t)));
}

void GlPolygonRaster::draw(std::size_t c, const ghosts::ShapedPolygons& polygons) {
    if (c >= channels_) throw Error(ErrorKind::Runtime, "the GL polygon raster has no channel " + std::to_string(c));
    for (std::size_t i = 0; i < polygons.polys.size(); ++i) {
        const auto& p = polygons.polys[i];
        const glm::dvec2 g = polygons.gradient(i);
        if (p.count == 0 || p.energy == 0.0) continue;
        // Its tile box, clamped to the frame, bounds the lists it joins (polygon_bins.comp finds the
        // same pixels or fewer: a kind that draws nothing joins none).
        glm::vec2 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
        for (std::uint32_t k = p.first; k < p.first + p.count; ++k) {
            lo = glm::min(lo, polygons.vertices[k]);
            hi = glm::max(hi, polygons.vertices[k]);
        }
        const auto tiles = [](double a, double b, int n) -> std::size_t {
            if (!(a <= b)) return std::size_t(n); // NaN: at most every tile
            const double t0 = std::clamp(std::floor(a) - 1.0, 0.0, n * double(kTile) - 1.0);
            const double t1 = std::clamp(std::ceil(b) + 1.0, 0.0, n * double(kTile) - 1.0);
            return static_cast<std::size_t>(t1) / kTile - static_cast<std::size_t>(t0) / kTile + 1;
        };
        const std::size_t entries = tiles(lo.x, hi.x, tilesX_) * tiles(lo.y, hi.y, tilesY_);
        if (stagedVertices_.size() + p.count > batch_ || stagedEntries_ + entries > listEntries_) flush();
        stagedEntries_ += entries;
        stagedPolygons_.push_back({static_cast<std::uint32_t>(stagedVertices_.size()), p.count,
                                   static_cast<std::uint32_t>(c), 0, p.energy, g.x, g.y});
        stagedVertices_.insert(stagedVertices_.end(), polygons.vertices.begin() + p.first,
                               polygons.vertices.begin() + p.first + p.count);
    }
}

void GlPolygonRaster::flush() {
    stagedEntries_ = 0;
    if (!stagedPolygons_.empty() && channels_ * tilesX_ * tilesY_ > 0) {
        vertices_.upload(stagedVertices_.data(), stagedVertices_.size() * sizeof(glm::vec2));
        polygons_.upload(stagedPolygons_.data(), stagedPolygons_.size() * sizeof(GpuPolygon));
        rasterise(0, stagedPolygons_.size());
    }
    stagedVertices_.clear();
    stagedPolygons_.clear();
}

void GlPolygonRaster::rasterise(std::size_t first, std::size_t count) {
    const std::size_t bins = channels_ * static_cast<std::size_t>(tilesX_) * tilesY_;
    if (count == 0 || bins == 0) return;
    const auto n = static_cast<GLuint>(count);
    if (prepared_.bytes() < count * kPrepared) prepared_.upload(nullptr, count * kPrepared);
    counts_.zeros(bins * sizeof(std::uint32_t));
    if (offsets_.bytes() != (bins + 1) * sizeof(std::uint32_t))
        offsets_.upload(nullptr, (bins + 1) * sizeof(std::uint32_t));
    vertices_.bind(0);
    polygons_.bind(1);
    accumulator_.bind(2);
    prepared_.bind(4);
    counts_.bind(5);
    offsets_.bind(7);
    // Pass 0: each polygon's kind, density and tiles; the bins' counts.
    bins_->use();
    bins_->set("width", width_);
    bins_->set("height", height_);
    bins_->set("count", static_cast<int>(n));
    bins_->set("firstPolygon", static_cast<int>(first));
    bins_->set("tilesX", tilesX_);
    bins_->set("tilesY", tilesY_);
    bins_->set("listPass", 0);
    dispatchGroups((n + kGroup - 1) / kGroup);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    scan_->use();
    scan_->set("n", static_cast<int>(bins));
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("polygon_bins.comp, bin_scan.comp");
    // The lists' length sizes their buffer (the one read-back of a batch); the counts become cursors.
    std::uint32_t entries = 0;
    glGetNamedBufferSubData(offsets_.id(), static_cast<GLintptr>(bins * sizeof(std::uint32_t)), sizeof entries,
                            &entries);
    if (entries > listEntries_ && count > 1) { // polygons made on the GPU: halves until the lists fit
        rasterise(first, count / 2);
        rasterise(first + count / 2, count - count / 2);
        return;
    }
    if (entries > 0) {
        if (lists_.bytes() < entries * sizeof(std::uint32_t)) lists_.upload(nullptr, entries * sizeof(std::uint32_t));
        glCopyNamedBufferSubData(offsets_.id(), counts_.id(), 0, 0,
                                 static_cast<GLsizeiptr>(bins * sizeof(std::uint32_t)));
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        lists_.bind(6);
        bins_->use();
        bins_->set("listPass", 1);
        dispatchGroups((n + kGroup - 1) / kGroup);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        tiles_->use();
        tiles_->set("width", width_);
        tiles_->set("height", height_);
        tiles_->set("tilesX", tilesX_);
        tiles_->set("tilesY", tilesY_);
        tiles_->set("bins", static_cast<int>(bins));
        tiles_->set("firstPolygon", static_cast<int>(first));
        tiles_->setDouble("scale", scale_);
        dispatchGroups(static_cast<GLuint>(bins));
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    }
    checkGl("polygon_tiles.comp");
}

bool GlPolygonRaster::cutsMeshes(const ghosts::ShapedTable& table) const {
    return cutMeshes_ && GlMeshCutter::takes(table);
}

std::vector<ghosts::MeshDrawn>
GlPolygonRaster::drawMeshes(const ghosts::ShapedTable& table, const std::vector<ghosts::MeshLight>& lights,
                            const std::vector<ghosts::MeshDraw>& draws, std::size_t channels,
                            const ghosts::ShapedRenderSettings& settings, float splatBelow) {
    if (channels > channels_)
        throw Error(ErrorKind::Runtime, "the GL polygon raster has no channel " + std::to_string(channels - 1));
    flush();
    if (!cutter_) cutter_ = std::make_unique<GlMeshCutter>();
    return cutter_->cut(table, lights, draws, channels, settings, splatBelow, frame_, vertices_, polygons_,
                        [this](std::size_t count) { rasterise(0, count); });
}

std::vector<std::vector<double>> GlPolygonRaster::finish() {
    flush();
    const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
    std::vector<std::vector<double>> out(channels_, std::vector<double>(pixels, 0.0));
    if (pixels == 0 || channels_ == 0) return out;
    const std::size_t all = channels_ * pixels;
    pixels_.upload(nullptr, all * sizeof(float));
    accumulator_.bind(2);
    pixels_.bind(3);
    image_->use();
    image_->set("pixels", static_cast<int>(all));
    image_->setDouble("scale", scale_);
    dispatchGroups(static_cast<GLuint>((all + kGroup - 1) / kGroup));
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("polygon_image.comp");
    std::vector<float> image(all);
    pixels_.download(image.data(), image.size() * sizeof(float));
    for (std::size_t c = 0; c < channels_; ++c)
        std::copy(image.begin() + static_cast<std::ptrdiff_t>(c * pixels),
                  image.begin() + static_cast<std::ptrdiff_t>((c + 1) * pixels), out[c].begin());
    return out;
}

} // namespace ff::gpu
