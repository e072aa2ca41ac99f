#include "gpu/gl_direct.h"

#include "gpu/gl_ghost_layout.h"
#include "gpu/gl_transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string_view>

namespace ff::gpu {

std::string_view embedded(std::string_view name);

namespace {

// std430 layout of shaders/direct_draw.comp's DirectGhost.
struct GpuDirectGhost {
    std::array<int, 4> box;
    float offsetX, offsetY, shape;
    int axes; // index of the first axis integral (direct_axes.comp)
    GpuChannels channels;
};
static_assert(sizeof(GpuDirectGhost) == 80);

constexpr int kTile = 16;      // direct_draw.comp's work group is one kTile x kTile tile
constexpr int kAxesGroup = 64; // direct_axes.comp's work group: one per ghost

int samples(const GpuDirectGhost& g) {
    return g.box[2] - g.box[0] + 1 + g.box[3] - g.box[1] + 1;
}

} // namespace

GlDirect::GlDirect(const GlContext&, std::size_t batch) : batch_(std::max<std::size_t>(batch, 1)) {
    // A fixed 16 x 16 work group: 256 invocations, within the 1024 every GL 4.5 device allows.
    program_ = std::make_unique<ComputeProgram>("direct_draw.comp", embedded("direct_draw.comp"), kTile * kTile);
    axes_ = std::make_unique<ComputeProgram>("direct_axes.comp", embedded("direct_axes.comp"), kAxesGroup);
}

GlDirect::~GlDirect() = default;

void GlDirect::add(const std::vector<fourier::Ghost>& ghosts, const std::vector<std::size_t>& which, int W, int H,
                   Buffer& image) {
    std::vector<GpuDirectGhost> list;
    list.reserve(which.size());
    for (std::size_t k : which) {
        const fourier::Ghost& g = ghosts[k];
        // The footprint as fourier::drawDirect clips it: pixels floor(c - e) .. floor(c + e) in the frame.
        const double ex = g.extentX(), ey = g.extentY();
        const int x0 = std::max(0, static_cast<int>(std::floor(g.x - ex))),
                  x1 = std::min(W - 1, static_cast<int>(std::floor(g.x + ex)));
        const int y0 = std::max(0, static_cast<int>(std::floor(g.y - ey))),
                  y1 = std::min(H - 1, static_cast<int>(std::floor(g.y + ey)));
        if (x1 < x0 || y1 < y0) continue;
        list.push_back({{x0, y0, x1, y1},
                        static_cast<float>(x0 - g.x),
                        static_cast<float>(y0 - g.y),
                        gpuShape(g),
                        0,
                        gpuChannels(g)});
    }
    // Batches whose axis integrals and tile lists each fit `batch_` entries, in ghost order: the
    // integrals of a batch (one work group per ghost), then its pixels (one work group per tile,
    // visiting the ghosts binned to it).
    const int tilesX = (W + kTile - 1) / kTile, tilesY = (H + kTile - 1) / kTile;
    const auto tilesOf = [](const GpuDirectGhost& g) {
        return static_cast<std::size_t>(g.box[2] / kTile - g.box[0] / kTile + 1) *
               static_cast<std::size_t>(g.box[3] / kTile - g.box[1] / kTile + 1);
    };
    std::vector<int> tileStart, tileGhosts;
    for (std::size_t begin = 0; begin < list.size();) {
        std::size_t end = begin, total = 0, entries = 0;
        while (end < list.size() && (end == begin || (total + static_cast<std::size_t>(samples(list[end])) <= batch_ &&
                                                      entries + tilesOf(list[end]) <= batch_))) {
            list[end].axes = static_cast<int>(total);
            total += static_cast<std::size_t>(samples(list[end]));
            entries += tilesOf(list[end++]);
        }
        // The tiles' ghost lists (compressed rows: counts, offsets, then the ghosts in order).
        tileStart.assign(static_cast<std::size_t>(tilesX) * tilesY + 1, 0);
        for (std::size_t k = begin; k < end; ++k)
            for (int ty = list[k].box[1] / kTile; ty <= list[k].box[3] / kTile; ++ty)
                for (int tx = list[k].box[0] / kTile; tx <= list[k].box[2] / kTile; ++tx)
                    ++tileStart[static_cast<std::size_t>(ty * tilesX + tx) + 1];
        for (std::size_t t = 1; t < tileStart.size(); ++t) tileStart[t] += tileStart[t - 1];
        tileGhosts.assign(entries, 0);
        std::vector<int> fill(tileStart.begin(), tileStart.end() - 1);
        for (std::size_t k = begin; k < end; ++k)
            for (int ty = list[k].box[1] / kTile; ty <= list[k].box[3] / kTile; ++ty)
                for (int tx = list[k].box[0] / kTile; tx <= list[k].box[2] / kTile; ++tx)
                    tileGhosts[static_cast<std::size_t>(fill[static_cast<std::size_t>(ty * tilesX + tx)]++)] =
                        static_cast<int>(k - begin);

        const auto count = static_cast<GLuint>(end - begin);
        ghosts_.upload(&list[begin], count * sizeof(GpuDirectGhost));
        integrals_.upload(nullptr, total * 4 * sizeof(float));
        tileStart_.upload(tileStart.data(), tileStart.size() * sizeof(int));
        tileGhosts_.upload(tileGhosts.data(), tileGhosts.size() * sizeof(int));
        ghosts_.bind(0);
        integrals_.bind(2);
        axes_->use();
        axes_->set("count", static_cast<int>(count));
        dispatchGroups(count);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        checkGl("direct_axes.comp");
        program_->use();
        program_->set("width", W);
        program_->set("height", H);
        program_->set("tilesX", tilesX);
        image.bind(1);
        tileStart_.bind(3);
        tileGhosts_.bind(4);
        glDispatchCompute(static_cast<GLuint>(tilesX), static_cast<GLuint>(tilesY), 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        checkGl("direct_draw.comp");
        begin = end;
    }
}

void GlDirect::draw(const std::vector<fourier::Ghost>& ghosts, const std::vector<std::size_t>& which,
                    fourier::FlareImage& image) {
    uploadImage(image, image_);
    add(ghosts, which, image.width, image.height, image_);
    downloadImage(image_, image);
}

} // namespace ff::gpu
