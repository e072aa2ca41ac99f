// fourierflare.ghost_report and fourierflare.GhostTable.

#include "core/error.h"
#include "core/file_io.h"
#include "ghosts/shaped_cache.h"
#include "ghosts/table_json.h"
#include "optics/lens_loader.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <pybind11/stl.h>

#include "bindings.h"
#include "python_support.h"
#include "report/ghost_report.h"

namespace ff::python {

using namespace pybind11::literals;

std::shared_ptr<ghosts::GhostTable> buildTable(const optics::Lens& lens, const ghosts::TableSettings& settings,
                                               bool useCache, const py::object& progress) {
    Interruptible watch(progress);
    DeferredReporter reporter;
    std::shared_ptr<ghosts::GhostTable> table;
    try {
        py::gil_scoped_release nogil;
        optics::requireTraceable(lens);
        table =
            std::make_shared<ghosts::GhostTable>(ghosts::tableFor(lens, settings, useCache, std::ref(watch), reporter));
    } catch (const Interrupted&) {
        reporter.flush();
        watch.raise();
    }
    reporter.flush();
    return table;
}

namespace {

py::object ghostReport(const optics::Lens& lens, double angleDeg, std::vector<double> wavelengths, double azimuthDeg,
                       int grid, const std::string& sampling, const std::string& sensor, const std::string& coating,
                       bool full) {
    report::GhostQuery q;
    q.angleDeg = angleDeg;
    q.azimuthDeg = azimuthDeg;
    q.wavelengthsNm = std::move(wavelengths);
    q.grid = grid;
    q.sampling = sampling;
    q.sensor = sensor;
    q.coating = coating;
    const trace::GhostAnalysisOptions options = q.options();
    nlohmann::json j;
    {
        py::gil_scoped_release nogil;
        optics::requireTraceable(lens);
        const trace::GhostReport r = trace::analyzeGhosts(lens, options);
        const std::size_t n = r.wavelengths.empty() ? 0 : r.wavelengths[0].ghosts.size();
        j = report::ghostReportJson(lens, q, r, n);
    }
    if (full) return fromJson(j);
    py::list rows;
    for (const auto& w : j["wavelengths"])
        for (const auto& g : w["ghosts"]) {
            py::dict row = fromJson(g);
            row["wavelength_nm"] = w["wavelength_nm"].get<double>();
            rows.append(row);
        }
    return rows;
}

py::array_t<double> doubles(const std::vector<double>& v) {
    return py::array_t<double>(v.size(), v.data());
}

py::dict ghostEntries(const ghosts::GhostTable& t, std::size_t g) {
    if (g >= t.ghosts.size())
        throw py::index_error("ghost " + std::to_string(g) + " of a table of " + std::to_string(t.ghosts.size()));
    const ghosts::TableGhost& gh = t.ghosts[g];
    const py::ssize_t W = static_cast<py::ssize_t>(gh.entries.size()),
                      A = static_cast<py::ssize_t>(gh.anglesDeg.size());
    const char* names[] = {"centroid_y_mm",  "sigma_r_mm",          "sigma_t_mm",          "flux",
                           "surviving",      "gaussian_width_r_mm", "gaussian_width_t_mm", "gaussian_peak",
                           "gaussian_error", "cos2_width_r_mm",     "cos2_width_t_mm",     "cos2_peak",
                           "cos2_error"};
    std::vector<py::array_t<double>> arrays;
    for (std::size_t k = 0; k < std::size(names); ++k) arrays.emplace_back(std::vector<py::ssize_t>{W, A});
    for (py::ssize_t w = 0; w < W; ++w)
        for (py::ssize_t a = 0; a < A; ++a) {
            const ghosts::TableEntry& e = gh.entries[w][a];
            const double v[] = {e.centroidY,       e.sigmaR,          e.sigmaT,        e.flux,           e.surviving,
                                e.gaussian.widthR, e.gaussian.widthT, e.gaussian.peak, e.gaussian.error, e.cos2.widthR,
                                e.cos2.widthT,     e.cos2.peak,       e.cos2.error};
            for (std::size_t k = 0; k < std::size(names); ++k) arrays[k].mutable_at(w, a) = v[k];
        }
    py::dict d("surfaces"_a = py::make_tuple(gh.pair.first + 1, gh.pair.second + 1), "path"_a = gh.pair.label(),
               "angles_deg"_a = doubles(gh.anglesDeg));
    for (std::size_t k = 0; k < std::size(names); ++k) d[names[k]] = arrays[k];
    return d;
}

py::dict entryAt(const ghosts::GhostTable& t, std::size_t g, std::size_t w, double angleDeg) {
    if (g >= t.ghosts.size()) throw py::index_error("no ghost " + std::to_string(g));
    if (w >= t.wavelengthsNm.size()) throw py::index_error("no wavelength " + std::to_string(w));
    const ghosts::TableEntry e = t.at(g, w, angleDeg);
    return py::dict("centroid_y_mm"_a = e.centroidY, "sigma_r_mm"_a = e.sigmaR, "sigma_t_mm"_a = e.sigmaT,
                    "flux"_a = e.flux, "surviving"_a = e.surviving,
                    "gaussian"_a = py::dict("width_r_mm"_a = e.gaussian.widthR, "width_t_mm"_a = e.gaussian.widthT,
                                            "peak"_a = e.gaussian.peak, "error"_a = e.gaussian.error),
                    "cos2"_a = py::dict("width_r_mm"_a = e.cos2.widthR, "width_t_mm"_a = e.cos2.widthT,
                                        "peak"_a = e.cos2.peak, "error"_a = e.cos2.error));
}

std::shared_ptr<ghosts::GhostTable> loadTable(const std::string& path) {
    py::gil_scoped_release nogil;
    return std::make_shared<ghosts::GhostTable>(ghosts::tableFromJson(readFileBytes(path, 1u << 30), path));
}

} // namespace

void bindGhosts(py::module_& m) {
    m.def("ghost_report", &ghostReport, "lens"_a, "angle_deg"_a, "wavelengths_nm"_a = std::vector<double>{550.0},
          py::kw_only(), "azimuth_deg"_a = 0.0, "grid"_a = 64, "sampling"_a = "reaim", "sensor"_a = "file",
          "coating"_a = "file", "full"_a = false,
          R"(Traces the direct image and every two-bounce ghost of a source at angle_deg (azimuth_deg
counter-clockwise, 0: the image at +y) and reports them, as `fourierflare ghosts --json` does.

Returns a list of dicts, one per ghost and wavelength (the wavelengths in the order given, the
ghosts strongest first): path ("R6→R5"), surfaces (1-based), launched, surviving, blocked,
surviving_fraction, relative_energy (to the direct image), energy_per_launched_ray, centroid_mm
[x, y] on the sensor, rms_radius_mm, axial_ratio (None on the axis), on_sensor_share, wavelength_nm.
full=True returns the command's whole report (the direct image and the totals too) as a dict.
grid: rays per side of each path's pupil grid (2..1024); sampling: reaim or paraxial-grid;
sensor: file or paraxial (the plane); coating: file, none or mgf2. Runs without the GIL.)");

    py::class_<ghosts::GhostTable, std::shared_ptr<ghosts::GhostTable>>(
        m, "GhostTable",
        R"(The ghost table of a lens over field angle: every two-bounce ghost's
centroid, spreads, flux and Gaussian and cos² fits at R, G, B wavelengths (docs/ghost-table.md).)")
        .def_static(
            "build",
            [](const optics::Lens& lens, int tableGrid, const std::string& sensor, const std::string& coating,
               double maxAngle, int tableAngles, bool useCache, const py::object& progress) {
                return buildTable(lens, ghosts::TableSettings::named(tableGrid, tableAngles, sensor, coating, maxAngle),
                                  useCache, progress);
            },
            "lens"_a, py::kw_only(), "table_grid"_a = 64, "sensor"_a = "file", "coating"_a = "file",
            "max_angle"_a = 0.0, "table_angles"_a = 25, "use_cache"_a = true, "progress"_a = py::none(),
            R"(Builds the lens's ghost table, or reads it from the cache (the CLI's: $FF_CACHE_DIR, else
~/.cache/fourierflare) when use_cache and an entry for the same lens bytes and settings exists.

The options are the CLI's --table-grid, --sensor, --coating, --max-angle (degrees; 0: the
sensor's half-diagonal plus 5 %) and --table-angles. progress(done, total) is
called as the build goes; an exception it raises, or Ctrl-C, stops the build and is raised here.
Runs without the GIL.)")
        .def_static("load", &loadTable, "path"_a, "Reads a table written by save() or `fourierflare table`.")
        .def(
            "save",
            [](const ghosts::GhostTable& t, const std::string& path) {
                py::gil_scoped_release nogil;
                writeFileAtomic(path, ghosts::tableToJson(t));
            },
            "path"_a, "Writes the table as JSON (docs/ghost-table.md), atomically.")
        .def(
            "to_json", [](const ghosts::GhostTable& t) { return ghosts::tableToJson(t); }, "The table as JSON text.")
        .def(
            "__len__", [](const ghosts::GhostTable& t) { return t.ghosts.size(); }, "The number of ghosts.")
        .def("ghost", &ghostEntries, "index"_a,
             R"(Ghost `index` (0-based) as a dict: surfaces (1-based), path, angles_deg (its field angles),
and arrays of shape (wavelengths, angles): centroid_y_mm, sigma_r_mm, sigma_t_mm, flux (relative to
the direct image), surviving, and the fits' gaussian_/cos2_ width_r_mm, width_t_mm, peak (per mm²),
error (relative L2).)")
        .def("at", &entryAt, "ghost"_a, "wavelength"_a, "angle_deg"_a,
             "Ghost `ghost`'s entry at wavelength index `wavelength`, interpolated at angle_deg, as a dict.")
        .def_property_readonly("lens_name", [](const ghosts::GhostTable& t) { return t.lensName; })
        .def_property_readonly("lens_file", [](const ghosts::GhostTable& t) { return t.lensFile; })
        .def_property_readonly("lens_hash", [](const ghosts::GhostTable& t) { return t.lensHash; })
        .def_property_readonly("settings_key", [](const ghosts::GhostTable& t) { return t.settingsKey; })
        .def_property_readonly("efl_mm", [](const ghosts::GhostTable& t) { return t.efl; })
        .def_property_readonly("sensor_z_mm", [](const ghosts::GhostTable& t) { return t.sensorZ; })
        .def_property_readonly("sensor_size_mm", [](const ghosts::GhostTable& t) { return t.sensorSizeMm; })
        .def_property_readonly("wavelengths_nm", [](const ghosts::GhostTable& t) { return doubles(t.wavelengthsNm); })
        .def_property_readonly(
            "angles_deg", [](const ghosts::GhostTable& t) { return doubles(t.anglesDeg); },
            "Every ghost's angles together, increasing, from 0.")
        .def_property_readonly("build_seconds", [](const ghosts::GhostTable& t) { return t.buildSeconds; })
        .def("__repr__", [](const ghosts::GhostTable& t) {
            return "<fourierflare.GhostTable of '" + t.lensName + "': " + std::to_string(t.ghosts.size()) +
                   " ghosts, " + std::to_string(t.anglesDeg.size()) + " angles>";
        });
}

} // namespace ff::python
