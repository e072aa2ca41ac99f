// fourierflare.compare: the flare models of one scene against the traced reference.

#include "core/error.h"
#include "optics/lens_loader.h"
#include "scene/comparison.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <pybind11/stl.h>
#include <random>

#include "bindings.h"
#include "python_support.h"

namespace ff::python {

using namespace pybind11::literals;

namespace {

namespace fs = std::filesystem;

// The report folder: `output` (created), or a fresh temporary one removed afterwards.
struct ReportFolder {
    explicit ReportFolder(const py::object& output) {
        if (!output.is_none()) {
            path = scene::reportFolder(py::cast<std::string>(py::str(output)));
            return;
        }
        std::random_device rd;
        path = scene::reportFolder(
            (fs::temp_directory_path() / ("fourierflare-compare-" + std::to_string(rd()) + std::to_string(rd())))
                .string());
        temporary = true;
    }
    ~ReportFolder() {
        std::error_code ec;
        if (temporary) fs::remove_all(path, ec);
    }
    ReportFolder(const ReportFolder&) = delete;
    ReportFolder& operator=(const ReportFolder&) = delete;
    fs::path path;
    bool temporary = false;
};

py::object compare(const optics::Lens& lens, const py::object& lights, const py::object& size, const py::object& output,
                   int grid, std::vector<int> ns, const std::string& diffraction, const py::object& sensorSize,
                   int tableGrid, const std::string& sampling, const std::string& sensor, const std::string& coating,
                   double maxAngle, int tableAngles, double fourierError, const std::string& backend,
                   const py::object& progress) {
    scene::ComparisonSettings s;
    s.lights = lightsFrom(lights);
    std::tie(s.width, s.height) = sizeFrom(size, "size");
    s.sensorMm = lens.sensorMm.value_or(std::make_pair(36.0, 24.0));
    if (!sensorSize.is_none()) s.sensorMm = py::cast<std::pair<double, double>>(sensorSize);
    if (!(s.sensorMm.first > 0.0 && s.sensorMm.second > 0.0 && std::isfinite(s.sensorMm.first) &&
          std::isfinite(s.sensorMm.second)))
        throw Error(ErrorKind::Usage, "sensor_size must be (width, height) in mm, both > 0");
    if (grid < 2 || grid > 1024) throw Error(ErrorKind::Usage, "grid must be 2..1024 rays per side");
    s.grid = grid;
    s.ns = std::move(ns);
    s.diffraction = scene::diffractionNamed(diffraction, "the diffraction (diffraction)");
    s.sampling = trace::samplingNamed(sampling);
    s.table = ghosts::TableSettings::named(tableGrid, tableAngles, sensor, coating, maxAngle);
    if (!(fourierError >= 1e-7 && fourierError <= 0.5))
        throw Error(ErrorKind::Usage, "fourier_error must be 1e-7..0.5");
    s.fourier.error = fourierError;
    s.commandLine = "fourierflare.compare (Python)";
    Interruptible watch(progress);
    DeferredReporter reporter;
    loadTablesThrough(s, watch, reporter);
    optics::requireTraceable(lens);
    drawOn(backend, s, reporter, true,
           s.diffraction != scene::DiffractionRule::Off); // last, after every argument was checked
    const ReportFolder folder(output);
    nlohmann::json report;
    try {
        py::gil_scoped_release nogil;
        report = scene::compareFlares(lens, s, folder.path);
    } catch (const Interrupted&) {
        reporter.flush();
        watch.raise();
    }
    reporter.flush();
    return fromJson(report);
}

} // namespace

void bindCompare(py::module_& m) {
    m.def("compare", &compare, "lens"_a, "lights"_a, "size"_a = std::make_pair(1920, 1080), "output"_a = py::none(),
          py::kw_only(), "grid"_a = 32, "fourier_n_sweep"_a = std::vector<int>{16, 32, 64, 128, 256},
          "diffraction"_a = "off", "sensor_size"_a = py::none(), "table_grid"_a = 64, "sampling"_a = "reaim",
          "sensor"_a = "file", "coating"_a = "file", "max_angle"_a = 0.0, "table_angles"_a = 25,
          "fourier_error"_a = 1e-3, "backend"_a = "auto", "progress"_a = py::none(),
          R"(The flare models of one scene against the traced reference, as `fourierflare compare` does
(docs/compare.md), returning its report.json as a dict: the reference's own error, shaped vs
traced, per profile (gaussian, cos2) fitted vs traced, fourier vs fitted and vs traced (relative L2,
PSNR, max error, flux ratio), the error against N (fourier_n_sweep), the Fourier plans and seconds.

lights: (x, y), (x, y, r, g, b) or dicts, in pixels; size: (width, height), 8..8192 each.
output: the report folder (images, difference pictures, report.md, error-vs-n.svg); None keeps the
numbers only (a temporary folder, removed). diffraction: off, physical or traced. The table's
options are GhostTable.build's. backend: 'cpu', 'gl' or 'auto', as the CLI's --backend (render's
docstring). Runs without the GIL.)");
}

} // namespace ff::python
