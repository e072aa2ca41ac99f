// fourierflare.render: the flare of lights as an image, in the CLI's `render` modes.

#include "core/error.h"
#include "core/units.h"
#include "ghosts/shaped_cache.h"
#include "optics/lens_loader.h"
#include "scene/flare_render.h"
#include "trace/traced_flare.h"

#include <cmath>
#include <pybind11/stl.h>

#include "bindings.h"
#include "python_support.h"

namespace ff::python {

using namespace pybind11::literals;

namespace {

struct RenderArgs {
    scene::RenderMode mode = scene::RenderMode::Traced;
    ghosts::Profile profile = ghosts::Profile::Gaussian;
    scene::DiffractionRule diffraction = scene::DiffractionRule::Physical;
    std::optional<std::pair<double, double>> angle;        ///< degrees: field, azimuth
    std::optional<std::pair<double, double>> sensorSizeMm; ///< default: the lens file's, else 36 x 24
    int grid = 32, spectral = 0;
    double refine = 1.0;
    std::string sampling = "reaim"; ///< traced
    ghosts::TableSettings table;
    bool useCache = true;
    double fourierError = 1e-3;
    int fourierN = 0;
    bool hybrid = true;
    std::string backend = "auto";
};

std::optional<std::pair<double, double>> angleFrom(const py::object& angle) {
    if (angle.is_none()) return std::nullopt;
    if (py::isinstance<py::float_>(angle) || py::isinstance<py::int_>(angle))
        return std::make_pair(py::cast<double>(angle), 0.0);
    const auto a = py::cast<std::vector<double>>(angle);
    if (a.size() != 2) throw Error(ErrorKind::Usage, "angle is degrees or (degrees, azimuth degrees)");
    return std::make_pair(a[0], a[1]);
}

void check(const RenderArgs& a, bool fromTable, bool haveLights) {
    auto usage = [](const std::string& s) { throw Error(ErrorKind::Usage, s); };
    if (a.diffraction == scene::DiffractionRule::Off) usage("diffraction must be physical or traced");
    if (a.grid < 2 || a.grid > 1024) usage("grid must be 2..1024 rays per side");
    if (a.spectral != 0 && (a.spectral < 8 || a.spectral > 16)) usage("spectral must be 0 or 8..16 wavelengths");
    if (!(a.refine >= 1.0 && a.refine <= 16.0)) usage("refine must be 1..16");
    if (!(a.fourierError >= 1e-7 && a.fourierError <= 0.5)) usage("fourier_error must be 1e-7..0.5");
    if (a.fourierN < 0 || a.fourierN > 2048) usage("fourier_n must be 0 (the budget's choice) or 1..2048");
    if (a.sensorSizeMm && !(a.sensorSizeMm->first > 0.0 && a.sensorSizeMm->second > 0.0 &&
                            std::isfinite(a.sensorSizeMm->first) && std::isfinite(a.sensorSizeMm->second)))
        usage("sensor_size must be (width, height) in mm, both > 0");
    if (a.angle && (!std::isfinite(a.angle->first) || !std::isfinite(a.angle->second)))
        usage("angle must be finite degrees");
    if (a.angle && a.mode != scene::RenderMode::Traced)
        usage("angle works with mode='traced'; give the lights' positions instead");
    if (a.angle && haveLights) usage("give either angle or lights, not both");
    if (!a.angle && !haveLights) usage("give lights (pixels) or, with mode='traced', a field angle");
    if (fromTable && a.mode != scene::RenderMode::Fitted && a.mode != scene::RenderMode::Fourier)
        usage("a GhostTable renders with mode='fitted' or 'fourier'; give the Lens for mode='" +
              std::string(scene::toString(a.mode)) + "'");
}

py::array_t<float> render(const py::object& source, const py::object& lightsIn, const py::object& size,
                          const std::string& mode, const py::object& angle, const std::string& ghostModel,
                          const std::string& diffraction, const py::object& sensorSize, int grid, double refine,
                          int spectral, int tableGrid, const std::string& sampling, const std::string& sensor,
                          const std::string& coating, double maxAngle, int tableAngles, bool useCache,
                          double fourierError, int fourierN, bool hybrid, const std::string& backend,
                          const py::object& progress) {
    RenderArgs a;
    a.mode = scene::renderModeNamed(mode, "the mode (mode)");
    a.profile = ghosts::profileNamed(ghostModel, "the ghost model (ghost_model)");
    a.diffraction = scene::diffractionNamed(diffraction, "the diffraction (diffraction)");
    a.angle = angleFrom(angle);
    if (!sensorSize.is_none()) a.sensorSizeMm = py::cast<std::pair<double, double>>(sensorSize);
    a.grid = grid;
    a.refine = refine;
    a.spectral = spectral;
    a.sampling = sampling;
    a.table = ghosts::TableSettings::named(tableGrid, tableAngles, sensor, coating, maxAngle);
    a.useCache = useCache;
    a.fourierError = fourierError;
    a.fourierN = fourierN;
    a.hybrid = hybrid;
    a.backend = backend;
    const auto [W, H] = sizeFrom(size, "size");
    const std::vector<ghosts::Light> lights = lightsFrom(lightsIn);
    const auto* table =
        py::isinstance<ghosts::GhostTable>(source) ? &py::cast<const ghosts::GhostTable&>(source) : nullptr;
    if (!table && !py::isinstance<optics::Lens>(source))
        throw py::type_error("render's source is a fourierflare.Lens or a fourierflare.GhostTable");
    const auto* lens = table ? nullptr : &py::cast<const optics::Lens&>(source);
    check(a, table != nullptr, !lights.empty());

    scene::FlareSettings s;
    s.mode = a.mode;
    s.profile = a.profile;
    s.diffraction = a.diffraction;
    s.sensorMm =
        a.sensorSizeMm.value_or(table ? table->sensorSizeMm : lens->sensorMm.value_or(std::make_pair(36.0, 24.0)));
    trace::TracedFlareOptions& t = s.traced;
    t.frame = {W, H, s.sensorMm.first / W};
    t.spectralSamples = a.spectral;
    t.sampling = trace::samplingNamed(a.sampling);
    t.grid = a.grid;
    t.refinement = a.refine;
    t.sensor = a.table.sensor;
    t.coating = a.table.coating;
    if (a.angle) s.field = trace::Field{degToRad(a.angle->first), degToRad(a.angle->second)};
    s.table = a.table;
    s.fourier.error = a.fourierError;
    s.fourier.fixedN = a.fourierN;
    s.fourier.hybrid = a.hybrid;
    s.useCache = a.useCache;
    s.loadTable = [&](const optics::Lens& l, const ghosts::TableSettings& ts) {
        py::gil_scoped_acquire gil;
        return std::move(*buildTable(l, ts, a.useCache, progress)); // the only owner
    };
    s.loadShaped = [&](const optics::Lens& l, const ghosts::TableSettings& ss) {
        return ghosts::shapedTableFor(l, ss, a.useCache, orNull(nullptr));
    };
    DeferredReporter reporter;
    if (!table) scene::requireLensFor(*lens, s);
    drawOn(a.backend, s, reporter, a.mode == scene::RenderMode::Shaped,
           a.mode == scene::RenderMode::Diffraction); // last, after every argument has been checked
    reporter.flush();
    fourier::FlareImage image;
    {
        py::gil_scoped_release nogil;
        image =
            std::move((table ? scene::renderFromTable(*table, lights, s) : scene::renderFlare(*lens, lights, s)).image);
    }
    return ownedArray(image.interleaved(), {H, W, 3});
}

} // namespace

void bindRender(py::module_& m) {
    m.def("render", &render, "source"_a, "lights"_a = py::none(), "size"_a = std::make_pair(1280, 720),
          "mode"_a = "traced", py::kw_only(), "angle"_a = py::none(), "ghost_model"_a = "gaussian",
          "diffraction"_a = "physical", "sensor_size"_a = py::none(), "grid"_a = 32, "refine"_a = 1.0, "spectral"_a = 0,
          "table_grid"_a = 64, "sampling"_a = "reaim", "sensor"_a = "file", "coating"_a = "file", "max_angle"_a = 0.0,
          "table_angles"_a = 25, "use_cache"_a = true, "fourier_error"_a = 1e-3, "fourier_n"_a = 0, "hybrid"_a = true,
          "backend"_a = "auto", "progress"_a = py::none(),
          R"(The flare of lights through a lens as a float32 array of shape (height, width, 3), linear RGB,
flux per pixel relative to the direct image of a unit light: what `fourierflare render` writes.

source: a Lens, or a GhostTable for mode 'fitted' or 'fourier'.
lights: a sequence of (x, y), (x, y, r, g, b) or {"x", "y", "flux": [r, g, b]} in pixels (origin
top-left, +y down); or, with mode='traced', angle=degrees or (degrees, azimuth) for one source.
size: (width, height) in pixels; the image spans the sensor's width (sensor_size (w, h) in mm,
default the lens file's, else 36 x 24).
mode: 'traced' (every ghost ray-traced; grid, refine, spectral), 'shaped' (the shaped ghosts),
'fitted' (the ghost table's ghost_model profiles drawn directly), 'fourier' (aggregated through
the separable Fourier series; fourier_error, fourier_n, and hybrid=False to
send every ghost through the series, as the CLI's --no-hybrid) or 'diffraction' (the iris's starburst;
diffraction='physical' or 'traced').
The table's options (table_grid, sensor, coating, max_angle, table_angles, use_cache, progress) are
GhostTable.build's and serve 'shaped', 'fitted' and 'fourier' (use_cache the diffraction's PSF too); sampling is the traced paths' pupil
sampling; sensor and coating serve every mode.
backend: where the flare is drawn (the Fourier series, the shaped polygons, the diffraction's
convolution), as the CLI's --backend: 'cpu', 'gl' (OpenGL 4.5 through EGL; llvmpipe without a GPU)
or 'auto' (gl on a GPU, else cpu). Runs without the GIL.)");
}

} // namespace ff::python
