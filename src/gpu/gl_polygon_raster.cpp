#include "gpu/gl_polygon_raster.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <string_view>

namespace ff::gpu {

std::string_view embedded(std::string_view name);

namespace {

constexpr int kGroup = 64;           // invocations per work group of both shaders
constexpr GLuint kMaxGroups = 65535; // work groups per dispatch dimension every GL 4.5 device allows

} // namespace

GlPolygonRaster::GlPolygonRaster(const GlContext&, std::size_t batch) : batch_(std::max<std::size_t>(batch, 64)) {
    edges_ = std::make_unique<ComputeProgram>("polygon_edges.comp", embedded("polygon_edges.comp"), kGroup);
    rows_ = std::make_unique<ComputeProgram>("polygon_rows.comp", embedded("polygon_rows.comp"), kGroup);
}

GlPolygonRaster::~GlPolygonRaster() = default;

void GlPolygonRaster::begin(const trace::ImageFrame& frame, std::size_t channels, double energyBound) {
    if (!(energyBound > 0.0) || !std::isfinite(energyBound))
        throw Error(ErrorKind::Runtime, "the GL polygon raster needs a positive, finite energy bound");
    width_ = std::max(frame.width, 0);
    height_ = std::max(frame.height, 0);
    channels_ = channels;
    // Every prefix sum stays below 2^62 units: one pixel holds at most energyBound.
    scale_ = std::ldexp(1.0, 62) / energyBound;
    stagedVertices_.clear();
    stagedPolygons_.clear();
    // The entries and the slopes (polygon_edges.comp), 64 bits each.
    accumulator_.zeros(std::max<std::size_t>(1, 2 * channels_ * height_ * (width_ + 2) * 2 * sizeof(std::uint32_t)));
}

void GlPolygonRaster::draw(std::size_t c, const ghosts::ShapedPolygons& polygons) {
    if (c >= channels_) throw Error(ErrorKind::Runtime, "the GL polygon raster has no channel " + std::to_string(c));
    for (std::size_t i = 0; i < polygons.polys.size(); ++i) {
        const auto& p = polygons.polys[i];
        const glm::dvec2 g = polygons.gradient(i);
        if (p.count == 0 || p.energy == 0.0) continue;
        if (stagedVertices_.size() + p.count > batch_) flush();
        stagedPolygons_.push_back({static_cast<std::uint32_t>(stagedVertices_.size()), p.count,
                                   static_cast<std::uint32_t>(c), 0, p.energy, g.x, g.y});
        stagedVertices_.insert(stagedVertices_.end(), polygons.vertices.begin() + p.first,
                               polygons.vertices.begin() + p.first + p.count);
    }
}

void GlPolygonRaster::flush() {
    if (stagedPolygons_.empty() || width_ == 0 || height_ == 0) {
        stagedVertices_.clear();
        stagedPolygons_.clear();
        return;
    }
    vertices_.upload(stagedVertices_.data(), stagedVertices_.size() * sizeof(glm::vec2));
    polygons_.upload(stagedPolygons_.data(), stagedPolygons_.size() * sizeof(GpuPolygon));
    const auto count = static_cast<GLuint>(stagedPolygons_.size());
    const GLuint groups = (count + kGroup - 1) / kGroup;
    vertices_.bind(0);
    polygons_.bind(1);
    accumulator_.bind(2);
    edges_->use();
    edges_->set("width", width_);
    edges_->set("height", height_);
    edges_->set("count", static_cast<int>(count));
    edges_->set("channels", static_cast<int>(channels_));
    edges_->setDouble("scale", scale_);
    glDispatchCompute(std::min(groups, kMaxGroups), (groups + kMaxGroups - 1) / kMaxGroups, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("polygon_edges.comp");
    stagedVertices_.clear();
    stagedPolygons_.clear();
}

std::vector<std::vector<double>> GlPolygonRaster::finish() {
    flush();
    const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
    std::vector<std::vector<double>> out(channels_, std::vector<double>(pixels, 0.0));
    if (pixels == 0 || channels_ == 0) return out;
    const int rows = static_cast<int>(channels_) * height_;
    image_.upload(nullptr, channels_ * pixels * sizeof(float));
    accumulator_.bind(2);
    image_.bind(3);
    rows_->use();
    rows_->set("width", width_);
    rows_->set("rows", rows);
    rows_->setDouble("scale", scale_);
    glDispatchCompute(static_cast<GLuint>((rows + kGroup - 1) / kGroup), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("polygon_rows.comp");
    std::vector<float> image(channels_ * pixels);
    image_.download(image.data(), image.size() * sizeof(float));
    for (std::size_t c = 0; c < channels_; ++c)
        std::copy(image.begin() + static_cast<std::ptrdiff_t>(c * pixels),
                  image.begin() + static_cast<std::ptrdiff_t>((c + 1) * pixels), out[c].begin());
    return out;
}

} // namespace ff::gpu
