#include "gpu/gl_composite.h"

#include "core/error.h"

#include <string>
#include <string_view>

namespace ff::gpu {

std::string_view embedded(std::string_view name);

GlCompositor::GlCompositor(const GlContext&) {
    program_ = std::make_unique<ComputeProgram>("composite.comp", embedded("composite.comp"), 256); // 16 x 16
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSide_);
}

GlCompositor::~GlCompositor() = default;

std::vector<float> GlCompositor::composite(const std::vector<float>& plate, int W, int H, const Buffer& flare) {
    if (W > maxSide_ || H > maxSide_)
        throwRuntimeError("the plate (" + std::to_string(W) + " x " + std::to_string(H) +
                          ") is larger than this device's textures (" + std::to_string(maxSide_) + ")");
    const std::size_t values = static_cast<std::size_t>(3) * W * H;
    if (plate.size() != values || flare.bytes() != values * sizeof(float))
        throwRuntimeError("GlCompositor: plate and flare sizes differ");
    plate_.upload(plate.data(), W, H);
    if (out_.bytes() != values * sizeof(float)) out_.upload(nullptr, values * sizeof(float));
    program_->use();
    program_->set("width", W);
    program_->set("height", H);
    plate_.bind(0);
    flare.bind(1);
    out_.bind(2);
    glDispatchCompute(static_cast<GLuint>((W + 15) / 16), static_cast<GLuint>((H + 15) / 16), 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGl("composite.comp");
    std::vector<float> out(values);
    out_.download(out.data(), values * sizeof(float));
    return out;
}

} // namespace ff::gpu
