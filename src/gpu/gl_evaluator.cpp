#include "gpu/gl_evaluator.h"

#include "fourier/evaluate.h"
#include "gpu/gl_transfer.h"

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

void GlEvaluator::add(const Buffer& z, int n, int m, double periodX, double periodY, int W, int H, Buffer& image) {
    if (n == 0 || m == 0) return;
    const int twoN = 2 * n, twoM = 2 * m;
    const std::vector<float> bx = fourier::seriesBasis(n, W, periodX), by = fourier::seriesBasis(m, H, periodY);
    basisX_.upload(bx.data(), bx.size() * sizeof(float));
    basisY_.upload(by.data(), by.size() * sizeof(float));
    const std::size_t rows = static_cast<std::size_t>(3) * twoN * H * sizeof(float);
    if (t_.bytes() != rows) t_.upload(nullptr, rows);

    const auto groups = [](int count, int size) { return static_cast<GLuint>((count + size - 1) / size); };
    rows_->use();
    rows_->set("twoN", twoN);
    rows_->set("twoM", twoM);
    rows_->set("height", H);
    z.bind(0);
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
    image.bind(2);
    glDispatchCompute(groups(W, pixels_->localSize()), static_cast<GLuint>(H), 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("evaluate_pixels.comp");
}

void GlEvaluator::evaluate(const fourier::Coefficients& z, fourier::FlareImage& image) {
    const int W = image.width, H = image.height;
    image_.zeros(static_cast<std::size_t>(3) * W * H * sizeof(float));
    if (z.n > 0 && z.m > 0) {
        uploadCoefficients(z, z_);
        add(z_, z.n, z.m, z.periodX, z.periodY, W, H, image_);
    }
    downloadImage(image_, image);
}

} // namespace ff::gpu
