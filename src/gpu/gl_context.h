#pragma once
// A headless OpenGL 4.5 core context through EGL, no window and no config (EGL_KHR_no_config_context).
// Hardware first: the EGL devices (EGL_EXT_device_enumeration) are tried, those that are not Mesa's
// software device before it; then Mesa's surfaceless platform, which on a machine without a GPU is
// llvmpipe. The context is current on the thread that created it and only there. Destroying it
// leaves its display initialised for the other contexts of the process (gl_context.cpp).

#include <memory>
#include <string>

namespace ff::gpu {

class GlContext {
  public:
    /// A context, or null with the reason in `why` (no EGL library, no device, no 4.5 core context).
    /// hardwareOnly: refuse a context whose renderer is a software rasteriser (llvmpipe, softpipe).
    static std::unique_ptr<GlContext> create(std::string& why, bool hardwareOnly = false);
    ~GlContext();
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    const std::string& renderer() const { return renderer_; } ///< GL_RENDERER and GL_VERSION
    bool hardware() const { return hardware_; }               ///< not a software rasteriser
    int maxWorkGroupInvocations() const { return maxInvocations_; }

  private:
    GlContext() = default;
    void* display_ = nullptr;
    void* context_ = nullptr;
    std::string renderer_;
    bool hardware_ = false;
    int maxInvocations_ = 0;
};

} // namespace ff::gpu
