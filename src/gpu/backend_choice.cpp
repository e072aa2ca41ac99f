#include "gpu/backend_choice.h"

#include "core/error.h"

namespace ff::gpu {

std::shared_ptr<GlBackend> openBackend(const std::string& name, std::string& why) {
    if (name != "cpu" && name != "gl" && name != "auto")
        throw Error(ErrorKind::Usage, "the backend is cpu, gl or auto, got '" + name + "'");
    if (name == "cpu") return nullptr;
    auto context = GlContext::create(why, name == "auto");
    if (!context && name == "gl") throw Error(ErrorKind::Runtime, "backend gl: no OpenGL 4.5 context: " + why);
    if (!context) return nullptr;
    return std::make_shared<GlBackend>(std::move(context));
}

GlBackend* glBackendOf(const fourier::FourierSettings& settings) {
    return dynamic_cast<GlBackend*>(settings.backend.get());
}

diffraction::Convolver* diffractionDevice(const fourier::FourierSettings& settings) {
    GlBackend* gl = glBackendOf(settings);
    return gl ? &gl->fft() : nullptr;
}

ghosts::PolygonRaster* polygonRaster(const fourier::FourierSettings& settings) {
    GlBackend* gl = glBackendOf(settings);
    return gl ? &gl->polygonRaster() : nullptr;
}

std::vector<float> compositeOnDevice(GlBackend& gl, int width, int height, const std::vector<float>& plateRgb) {
    if (width > gl.maxCompositeSide() || height > gl.maxCompositeSide()) return {};
    return gl.composite(plateRgb);
}

} // namespace ff::gpu
