#include "gpu/gl_sampled.h"

#include "gpu/gl_ghost_layout.h"
#include "gpu/gl_transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string_view>

namespace ff::gpu {

std::string_view embedded(std::string_view name);

namespace {

// std430 layout of shaders/sampled_coefficients.comp's SampledGhost.
struct GpuSampledGhost {
    float firstU, firstV, stepU, stepV;
    int width, height, offset, pad;
};
static_assert(sizeof(GpuSampledGhost) == 32);

// Per-ghost slices kept on the GPU at once: ghosts per dispatch bounded by 64 MiB of slices.
constexpr std::size_t kSliceBytes = std::size_t(64) << 20;

} // namespace

GlSampled::GlSampled(const GlContext& context) {
    const int local = std::max(1, std::min(256, context.maxWorkGroupInvocations()));
    terms_ =
        std::make_unique<ComputeProgram>("sampled_coefficients.comp", embedded("sampled_coefficients.comp"), local);
    sum_ = std::make_unique<ComputeProgram>("sum_coefficients.comp", embedded("sum_coefficients.comp"), local);
}

GlSampled::~GlSampled() = default;

void GlSampled::add(const std::vector<fourier::SampledGhost>& ghosts, int n, int m, double periodX, double periodY,
                    Buffer& z) {
    fourier::checkSampled(ghosts, n, m, periodX, periodY);
    if (ghosts.empty() || n == 0 || m == 0) return;
    std::vector<GpuSampledGhost> list;
    std::vector<float> values;
    for (const auto& g : ghosts) {
        list.push_back({periodFraction(g.x0 + 0.5 * g.step, periodX), periodFraction(g.y0 + 0.5 * g.step, periodY),
                        static_cast<float>(g.step / periodX), static_cast<float>(g.step / periodY), g.width, g.height,
                        static_cast<int>(values.size()), 0});
        values.insert(values.end(), g.values.begin(), g.values.end());
    }
    ghosts_.upload(list.data(), list.size() * sizeof(GpuSampledGhost));
    values_.upload(values.data(), values.size() * sizeof(float));
    const int entries = 3 * 4 * n * m;
    const std::size_t sliceBytes = static_cast<std::size_t>(entries) * sizeof(float);
    const int chunk = static_cast<int>(std::clamp<std::size_t>(kSliceBytes / sliceBytes, 1, list.size()));
    if (slices_.bytes() < chunk * sliceBytes) slices_.upload(nullptr, chunk * sliceBytes);
    for (int first = 0; first < static_cast<int>(list.size()); first += chunk) {
        const int count = std::min(chunk, static_cast<int>(list.size()) - first);
        terms_->use();
        terms_->set("first", first);
        terms_->set("N", n);
        terms_->set("M", m);
        terms_->set("periodX", static_cast<float>(periodX));
        terms_->set("periodY", static_cast<float>(periodY));
        ghosts_.bind(0);
        values_.bind(1);
        slices_.bind(2);
        glDispatchCompute(static_cast<GLuint>(count), 1, 1); // one work group per ghost
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        checkGl("sampled_coefficients.comp");
        sum_->use();
        sum_->set("count", count);
        sum_->set("entries", entries);
        slices_.bind(0);
        z.bind(1);
        glDispatchCompute(static_cast<GLuint>((entries + sum_->localSize() - 1) / sum_->localSize()), 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        checkGl("sum_coefficients.comp");
    }
}

void GlSampled::accumulate(const std::vector<fourier::SampledGhost>& ghosts, fourier::Coefficients& z) {
    uploadCoefficients(z, z_);
    add(ghosts, z.n, z.m, z.periodX, z.periodY, z_);
    downloadCoefficients(z_, z);
}

} // namespace ff::gpu
