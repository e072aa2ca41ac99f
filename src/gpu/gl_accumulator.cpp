#include "gpu/gl_accumulator.h"

#include "core/error.h"
#include "gpu/gl_ghost_layout.h"
#include "gpu/gl_transfer.h"

#include <algorithm>
#include <string_view>

namespace ff::gpu {

std::string_view embedded(std::string_view name);

namespace {

// std430 layout of shaders/accumulate.comp's Ghost.
struct GpuGhost {
    float u, v, shape, pad;
    GpuChannels channels;
};
static_assert(sizeof(GpuGhost) == 64);

} // namespace

GlAccumulator::GlAccumulator(const GlContext& context) {
    localSize_ = std::max(1, std::min(256, context.maxWorkGroupInvocations()));
    program_ = std::make_unique<ComputeProgram>("accumulate.comp", embedded("accumulate.comp"), localSize_);
}

GlAccumulator::~GlAccumulator() = default;

void GlAccumulator::accumulate(const std::vector<fourier::Ghost>& ghosts, const fourier::Plan& plan,
                               const fourier::FourierSettings& settings, Buffer& z) {
    if (settings.gaussianForm != fourier::GaussianForm::Periodised)
        throw Error(ErrorKind::Usage,
                    "the GL accumulation computes periodised Gaussian coefficients only (no erf on the GPU)");
    const std::size_t values = static_cast<std::size_t>(3) * 4 * plan.n * plan.m;
    z.zeros(values * sizeof(float));
    if (values == 0) return;
    std::vector<GpuGhost> list;
    for (std::size_t k = 0; k < ghosts.size(); ++k) {
        if (plan.route[k] != fourier::Route::Fourier) continue;
        const fourier::Ghost& g = ghosts[k];
        list.push_back(
            {periodFraction(g.x, plan.periodX), periodFraction(g.y, plan.periodY), gpuShape(g), 0.0f, gpuChannels(g)});
    }
    if (list.empty()) return;
    ghosts_.upload(list.data(), list.size() * sizeof(GpuGhost));
    program_->use();
    program_->set("count", static_cast<int>(list.size()));
    program_->set("N", plan.n);
    program_->set("M", plan.m);
    program_->set("periodX", static_cast<float>(plan.periodX));
    program_->set("periodY", static_cast<float>(plan.periodY));
    program_->set("dropDc", settings.dropDc ? 1 : 0);
    ghosts_.bind(0);
    z.bind(1);
    const int invocations = 3 * plan.n * plan.m;
    glDispatchCompute(static_cast<GLuint>((invocations + localSize_ - 1) / localSize_), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("accumulate.comp");
}

fourier::Coefficients GlAccumulator::accumulate(const std::vector<fourier::Ghost>& ghosts, const fourier::Plan& plan,
                                                const fourier::FourierSettings& settings) {
    fourier::Coefficients co = fourier::Coefficients::zeros(plan);
    accumulate(ghosts, plan, settings, z_);
    if (co.n > 0 && co.m > 0) downloadCoefficients(z_, co);
    return co;
}

} // namespace ff::gpu
