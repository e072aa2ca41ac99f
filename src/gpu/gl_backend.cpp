#include "gpu/gl_backend.h"

#include "core/stopwatch.h"
#include "fourier/aggregate.h"
#include "gpu/gl_transfer.h"

#include <algorithm>
#include <chrono>

namespace ff::gpu {

namespace {

// Seconds since t (after the GPU has finished what was queued), and t moved to now.
double since(Clock::time_point& t) {
    glFinish();
    return lap(t);
}

} // namespace

GlBackend::GlBackend(std::unique_ptr<GlContext> context) : context_(std::move(context)) {
    accumulator_ = std::make_unique<GlAccumulator>(*context_);
    evaluator_ = std::make_unique<GlEvaluator>(*context_);
    direct_ = std::make_unique<GlDirect>(*context_);
    compositor_ = std::make_unique<GlCompositor>(*context_);
}

GlBackend::~GlBackend() = default;

std::string GlBackend::describe() const {
    return "gl: " + context_->renderer();
}

void GlBackend::begin(int width, int height) {
    width_ = width;
    height_ = height;
    image_.zeros(static_cast<std::size_t>(3) * width * height * sizeof(float));
}

void GlBackend::addLevel(const std::vector<fourier::Ghost>& ghosts, const fourier::Plan& plan,
                         const fourier::FourierSettings& settings, fourier::StageSeconds& seconds) {
    auto t = std::chrono::steady_clock::now();
    if (plan.fourier > 0 && plan.n > 0 && plan.m > 0) {
        // The GPU has no erf: the exact and A&S Gaussian forms are accumulated on the CPU and uploaded.
        const bool anyGaussian = std::any_of(
            ghosts.begin(), ghosts.end(), [](const fourier::Ghost& g) { return g.shape == fourier::Shape::Gaussian; });
        if (settings.gaussianForm == fourier::GaussianForm::Periodised || !anyGaussian) {
            accumulator_->accumulate(ghosts, plan, settings, z_);
        } else {
            uploadCoefficients(fourier::accumulate(ghosts, plan, settings), z_);
        }
        seconds.accumulate += since(t);
        evaluator_->add(z_, plan.n, plan.m, plan.periodX, plan.periodY, width_, height_, image_);
        seconds.evaluate += since(t);
    }
    std::vector<std::size_t> direct;
    for (std::size_t k = 0; k < ghosts.size(); ++k)
        if (plan.route[k] == fourier::Route::Direct) direct.push_back(k);
    direct_->add(ghosts, direct, width_, height_, image_);
    seconds.direct += since(t);
}

void GlBackend::finish(fourier::FlareImage& image) {
    image = fourier::FlareImage(width_, height_);
    downloadImage(image_, image);
}

std::vector<float> GlBackend::composite(const std::vector<float>& plate) {
    return compositor_->composite(plate, width_, height_, image_);
}

GlFft& GlBackend::fft() {
    if (!fft_) fft_ = std::make_unique<GlFft>(*context_);
    return *fft_;
}

GlPolygonRaster& GlBackend::polygonRaster() {
    if (!polygons_) polygons_ = std::make_unique<GlPolygonRaster>(*context_);
    return *polygons_;
}

} // namespace ff::gpu
