#pragma once
// What the Python module's bindings share: ff::Error as Python exceptions, diagnostics to Python's
// logging, progress callbacks that can stop long work (Ctrl-C), numpy arrays that own the C++
// buffers, JSON as Python objects, and lights and sizes read from Python values.

#include "core/reporter.h"
#include "ghosts/instancing.h"
#include "ghosts/shaped_cache.h"
#include "gpu/backend_choice.h"

#include <nlohmann/json_fwd.hpp>

#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <string>
#include <utility>
#include <vector>

namespace ff::python {

namespace py = pybind11;

/// fourierflare.Error (a RuntimeError), InputError and UsageError (both also ValueError). Each
/// carries `file`, `line`, `column` (0: not known) and `message` (without the location); str() is
/// "file:line:column: message".
void registerErrors(py::module_& m);

/// Collects diagnostics from any thread while the GIL is released; flush() (GIL held) hands them to
/// the "fourierflare" logger: notes at INFO, warnings at WARNING.
class DeferredReporter final : public Reporter {
  public:
    void report(const Diagnostic& d) override;
    void flush();
    ~DeferredReporter() override;

  private:
    std::mutex mutex_;
    std::vector<Diagnostic> pending_;
};

/// Thrown through the C++ work when a progress callback raised or Ctrl-C was pressed.
struct Interrupted {};

/// A progress callback for long work run without the GIL: each call takes the GIL, runs Python's
/// signal handlers (Ctrl-C raises KeyboardInterrupt there) and calls `callback(done, total)` when
/// one was given. A Python exception from either stops the work (Interrupted); raise() re-raises it.
class Interruptible {
  public:
    explicit Interruptible(py::object callback) : callback_(std::move(callback)) {}
    void operator()(std::size_t done, std::size_t total);
    /// GIL held, after catching Interrupted: raises the Python exception that stopped the work.
    [[noreturn]] void raise();

  private:
    py::object callback_;
    std::mutex mutex_;
    std::unique_ptr<py::error_already_set> error_;
    std::atomic<bool> stopped_{false};
};

/// Sets the table loaders of scene settings (SimulationSettings, ComparisonSettings): both tables
/// from the cache or built and cached, a ghost table's build followed by `watch`, notes to `reporter`.
template <class Settings>
void loadTablesThrough(Settings& s, Interruptible& watch, DeferredReporter& reporter) {
    s.loadTable = [&watch, &reporter](const optics::Lens& l, const ghosts::TableSettings& t) {
        return ghosts::tableFor(l, t, true, std::ref(watch), reporter);
    };
    s.loadShaped = [&reporter](const optics::Lens& l, const ghosts::TableSettings& t) {
        return ghosts::shapedTableFor(l, t, true, reporter);
    };
}

/// Scene settings (FlareSettings, SimulationSettings, ComparisonSettings) drawn on the backend named
/// as the CLI's --backend: "cpu", "gl" (OpenGL 4.5 through EGL, llvmpipe without a GPU; ff::Error
/// when there is none) or "auto" (gl on a GPU, else the CPU, with a note to `reporter`). Sets the
/// Fourier backend, and where asked the shaped polygons' raster and the diffraction's convolution
/// (each made on the device when set). Call on the thread that then runs the work: a GL context is
/// current on its own thread only.
template <class Settings>
void drawOn(const std::string& backend, Settings& s, Reporter& reporter, bool shaped, bool diffraction) {
    std::string why;
    s.fourier.backend = gpu::openBackend(backend, why);
    if (!s.fourier.backend && backend == "auto") reporter.note({}, "backend auto: no GPU (" + why + "), using the CPU");
    if (shaped) s.raster = gpu::polygonRaster(s.fourier);
    if (diffraction) s.convolver = gpu::diffractionDevice(s.fourier);
}

/// A float32 array of the given shape that owns `data` (moved, not copied).
py::array_t<float> ownedArray(std::vector<float>&& data, std::vector<py::ssize_t> shape);

/// JSON as Python objects (dict, list, str, int, float, bool, None).
py::object fromJson(const nlohmann::json& j);

/// Lights from a sequence of (x, y), (x, y, r, g, b) or {"x", "y", "flux": [r, g, b]} (pixels; flux
/// of the light's direct image, default 1 per channel).
std::vector<ghosts::Light> lightsFrom(const py::handle& lights);

/// (width, height) in pixels, each 1..16384.
std::pair<int, int> sizeFrom(const py::handle& size, const char* what);

} // namespace ff::python
