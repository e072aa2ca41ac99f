// fourierflare.simulate: a lens's flare on a plate held in a numpy array.

#include "core/error.h"
#include "image/light_detection.h"
#include "image/plate.h"
#include "optics/lens_loader.h"
#include "scene/simulation.h"

#include <pybind11/stl.h>

#include "bindings.h"
#include "python_support.h"

namespace ff::python {

using namespace pybind11::literals;

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// The plate: (height, width) or (height, width, channels); names default to Y, -, RGB, RGBA.
image::Plate plateFrom(const FloatArray& a, const py::object& channelNames) {
    if (a.ndim() != 2 && a.ndim() != 3)
        throw Error(ErrorKind::Usage, "the plate is an array of shape (height, width) or (height, width, channels)");
    const int H = static_cast<int>(a.shape(0)), W = static_cast<int>(a.shape(1));
    const std::size_t C = a.ndim() == 3 ? static_cast<std::size_t>(a.shape(2)) : 1;
    std::vector<std::string> names;
    if (!channelNames.is_none())
        names = py::cast<std::vector<std::string>>(channelNames);
    else if (C == 1)
        names = {"Y"};
    else if (C == 3)
        names = {"R", "G", "B"};
    else if (C == 4)
        names = {"R", "G", "B", "A"};
    else
        throw Error(ErrorKind::Usage, "a plate of " + std::to_string(C) + " channels needs their names (channels=)");
    if (names.size() != C)
        throw Error(ErrorKind::Usage,
                    std::to_string(names.size()) + " channel names for " + std::to_string(C) + " channels");
    std::vector<float> pixels(a.data(), a.data() + a.size());
    return image::plateFromPixels("<plate array>", W, H, std::move(names), std::move(pixels));
}

py::list lightsOut(const scene::SimulatedPlate& r, bool given) {
    py::list out;
    for (std::size_t i = 0; i < r.lights.size(); ++i) {
        const ghosts::Light& l = r.lights[i];
        py::dict d("x"_a = l.xPx, "y"_a = l.yPx, "flux"_a = std::vector<double>(l.flux.begin(), l.flux.end()));
        if (!given) d["pixels"] = r.found.lights[i].pixels, d["peak"] = r.found.lights[i].peak;
        out.append(d);
    }
    return out;
}

py::dict simulate(const FloatArray& plateArray, const optics::Lens& lens, const py::object& lights,
                  const py::object& channels, const std::string& ghostModel, const std::string& diffraction,
                  double flareGain, double diffractionGain, const py::object& sensorSize, double fov,
                  const std::string& threshold, int block, int tableGrid, const std::string& sensor,
                  const std::string& coating, double maxAngle, int tableAngles, double fourierError, int fourierN,
                  const std::string& backend, const py::object& progress) {
    const image::Plate plate = plateFrom(plateArray, channels);
    scene::SimulationSettings s;
    s.ghostModel = scene::ghostModelNamed(ghostModel, "the ghost model (ghost_model)");
    s.diffraction = scene::diffractionNamed(diffraction, "the diffraction (diffraction)");
    s.gain = flareGain;
    s.diffractionGain = diffractionGain;
    if (!sensorSize.is_none()) {
        const auto size = py::cast<std::pair<double, double>>(sensorSize);
        if (!(size.first > 0.0 && size.second > 0.0 && std::isfinite(size.first) && std::isfinite(size.second)))
            throw Error(ErrorKind::Usage, "sensor_size must be (width, height) in mm, both > 0");
        s.sensorWidthMm = size.first;
    }
    s.fovDeg = fov;
    s.detection = image::parseThreshold(threshold);
    if (block < 2 || block > 4096) throw Error(ErrorKind::Usage, "block must be 2..4096 pixels");
    s.detection.blockSize = block;
    s.lights = lightsFrom(lights);
    s.table = ghosts::TableSettings::named(tableGrid, tableAngles, sensor, coating, maxAngle);
    if (!(fourierError >= 1e-7 && fourierError <= 0.5))
        throw Error(ErrorKind::Usage, "fourier_error must be 1e-7..0.5");
    if (fourierN < 0 || fourierN > 2048) throw Error(ErrorKind::Usage, "fourier_n must be 0 or 1..2048");
    s.fourier.error = fourierError;
    s.fourier.fixedN = fourierN;
    Interruptible watch(progress);
    DeferredReporter reporter;
    loadTablesThrough(s, watch, reporter);
    scene::requireLensFor(lens, s);
    // The backend last, after every argument has been checked. As the CLI: the GL backend draws the
    // shaped polygons, or aggregates the fitted models and composites on the device.
    drawOn(backend, s, reporter, s.ghostModel == scene::GhostModel::Shaped,
           s.diffraction != scene::DiffractionRule::Off);
    if (gpu::GlBackend* gl = gpu::glBackendOf(s.fourier); gl && s.ghostModel != scene::GhostModel::Shaped)
        s.deviceComposite = [gl](const image::Plate& p) {
            return gpu::compositeOnDevice(*gl, p.width, p.height, p.rgb());
        };
    const bool given = !s.lights.empty();
    scene::SimulatedPlate r;
    try {
        py::gil_scoped_release nogil;
        scene::Simulation sim(lens, std::move(s), reporter);
        r = sim.run(plate);
    } catch (const Interrupted&) {
        reporter.flush();
        watch.raise();
    }
    reporter.flush();
    const py::ssize_t H = plate.height, W = plate.width;
    py::dict out;
    out["ghosts"] = ownedArray(std::move(r.ghosts), {H, W, 3});
    out["diffraction"] = ownedArray(std::move(r.diffraction), {H, W, 3});
    out["light_pixels"] = ownedArray(std::move(r.lightPixels), {H, W, 3});
    out["flare"] = ownedArray(std::move(r.flare), {H, W, 3});
    out["composite"] = ownedArray(std::move(r.composite), {H, W, 3});
    out["lights"] = lightsOut(r, given);
    out["threshold"] = given ? py::object(py::none()) : py::object(py::float_(r.found.threshold));
    out["flare_summary"] = r.flareText;
    out["diffraction_summary"] = r.diffractionText;
    return out;
}

} // namespace

void bindSimulate(py::module_& m) {
    m.def("simulate", &simulate, "plate"_a, "lens"_a, py::kw_only(), "lights"_a = py::none(), "channels"_a = py::none(),
          "ghost_model"_a = "shaped", "diffraction"_a = "physical", "flare_gain"_a = 1.0, "diffraction_gain"_a = 1.0,
          "sensor_size"_a = py::none(), "fov"_a = 0.0, "threshold"_a = "2", "block"_a = 32, "table_grid"_a = 64,
          "sensor"_a = "file", "coating"_a = "file", "max_angle"_a = 0.0, "table_angles"_a = 25,
          "fourier_error"_a = 1e-3, "fourier_n"_a = 0, "backend"_a = "auto", "progress"_a = py::none(),
          R"(The lens's flare on an HDR plate, as `fourierflare simulate` makes it (docs/simulate.md).

plate: a float array of shape (height, width[, channels]), linear; channels named by `channels`
(default Y; R, G, B; or R, G, B, A); its lights are found above `threshold` (luminance: "2",
"max:0.25" or "p:99.9"; extended sources split into blocks of `block` pixels) unless `lights`
gives them ((x, y), (x, y, r, g, b) or dicts, in pixels).
ghost_model: shaped, gaussian or cos2; diffraction: physical, traced or off; flare_gain and
diffraction_gain scale the layers (1 = physical). The plate spans the sensor's width: sensor_size
(w, h) in mm, or fov (horizontal degrees), else the lens file's, else 36 mm.
Returns a dict: ghosts, diffraction (the lights as the iris draws them, cores included),
light_pixels (the lights' pixels the diffraction spreads: the EXR's `lights` layer), flare (= ghosts
+ diffraction) and composite (= plate + flare - light_pixels) as float32 arrays (height, width, 3); lights (x, y, flux, and pixels and peak when found); threshold
(the absolute luminance used, None when lights were given); flare_summary, diffraction_summary.
backend: 'cpu', 'gl' or 'auto', as the CLI's --backend (render's docstring). Runs without the GIL;
progress(done, total) follows a ghost table's build.)");
}

} // namespace ff::python
