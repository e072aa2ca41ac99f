#pragma once
// The drawing backend by name, as the CLI's --backend and the Python module's backend= choose it:
// "cpu", "gl" (OpenGL 4.5 compute through EGL; llvmpipe without a GPU) or "auto" (gl on a GPU, else
// cpu). One choice, one meaning, for every command and call.

#include "gpu/gl_backend.h"

#include <memory>
#include <string>
#include <vector>

namespace ff::gpu {

/// The GL backend `name` asks for, or null for the CPU. "cpu": null. "gl": a backend on any OpenGL
/// 4.5 context, software included; ff::Error (Runtime) with the reason when there is none. "auto": a
/// backend where the renderer is not a software rasteriser, else null with the reason in `why`.
/// ff::Error (Usage) for another name.
std::shared_ptr<GlBackend> openBackend(const std::string& name, std::string& why);

/// The settings' GL backend, or null when they draw on the CPU.
GlBackend* glBackendOf(const fourier::FourierSettings& settings);

/// The diffraction's convolution on the settings' GL backend, or null (FFTW on the CPU).
diffraction::Convolver* diffractionDevice(const fourier::FourierSettings& settings);

/// The shaped ghosts' polygon raster of the settings' GL backend, or null (the CPU draws them).
ghosts::PolygonRaster* polygonRaster(const fourier::FourierSettings& settings);

/// plate + the backend's last frame, composited on the GPU (R, G, B interleaved, width x height);
/// empty where the frame is larger than the device composites, the caller then compositing on the CPU.
std::vector<float> compositeOnDevice(GlBackend& gl, int width, int height, const std::vector<float>& plateRgb);

} // namespace ff::gpu
