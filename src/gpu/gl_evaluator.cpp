#include "gpu/gl_evaluator.h"

#include "fourier/evaluate.h"

#include <algorithm>
#include <string_view>

namespace ff::gpu {

std::string_view embedded(std::string_view name);

GlEvaluator::GlEvaluator(const GlContext& context) {
    // Work-group size: 256 where the device allows it (a multiple of the usual 32/64-wide SIMD).
    const int local = std::max(1, std::min(256, context.maxWorkGroupInvocations()));
    rows_ = std::make_unique<ComputeProgram>("evaluate_rows.comp", embedded("evaluate_rows.comp"), local);
    pixels_ = std::make_unique<ComputeProgram>("evaluate_pixels.comp", embedded("evaluate_pixels.comp"), local);
}

GlEvaluator::~GlEvaluator() = default;

void GlEvaluator::evaluate(const fourier::Coefficients& z, fourier::FlareImage& image) {
    for (auto& ch : image.channel) std::fill(ch.begin(), ch.end(), 0.0f);
    if (z.n == 0 || z.m == 0) return;
    const int W = image.width, H = image.height, twoN = 2 * z.n, twoM = 2 * z.m;
    std::vector<float> zf(static_cast<std::size_t>(3) * twoN * twoM);
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < z.z[c].size(); ++i) zf[static_cast<std::size_t>(c) * twoN * twoM + i] = static_cast<float>(z.z[c][i]);
    const std::vector<float> bx = fourier::seriesBasis(z.n, W, z.periodX), by = fourier::seriesBasis(z.m, H, z.periodY);
    z_.upload(zf.data(), zf.size() * sizeof(float));
    basisX_.upload(bx.data(), bx.size() * sizeof(float));
    basisY_.upload(by.data(), by.size() * sizeof(float));
    t_.upload(nullptr, static_cast<std::size_t>(3) * twoN * H * sizeof(float));
    image_.upload(nullptr, static_cast<std::size_t>(3) * W * H * sizeof(float));

    const auto groups = [](int n, int size) { return static_cast<GLuint>((n + size - 1) / size); };
    rows_->use();
    rows_->set("twoN", twoN);
    rows_->set("twoM", twoM);
    rows_->set("height", H);
    z_.bind(0);
    basisY_.bind(1);
    t_.bind(2);
    glDispatchCompute(groups(H, rows_->localSize()), static_cast<GLuint>(3 * twoN), 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    checkGl("evaluate_rows.comp");

    pixels_->use();
    pixels_->set("twoN", twoN);
    pixels_->set("width", W);
    pixels_->set("height", H);
    t_.bind(0);
    basisX_.bind(1);
    image_.bind(2);
    glDispatchCompute(groups(W, pixels_->localSize()), static_cast<GLuint>(H), 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("evaluate_pixels.comp");

    std::vector<float> planes(static_cast<std::size_t>(3) * W * H);
    image_.download(planes.data(), planes.size() * sizeof(float));
    for (int c = 0; c < 3; ++c)
        std::copy_n(planes.begin() + static_cast<long>(c) * W * H, static_cast<std::size_t>(W) * H, image.channel[c].begin());
}

} // namespace ff::gpu
