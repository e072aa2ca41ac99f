// fourierflare.Lens: a lens prescription and its first-order optics.

#include "core/units.h"
#include "optics/lens_loader.h"

#include <nlohmann/json.hpp>

#include <pybind11/stl.h>

#include "bindings.h"
#include "python_support.h"
#include "report/lens_report.h"

namespace ff::python {

using namespace pybind11::literals;

namespace {

std::string zoomText(const py::object& zoom) {
    if (zoom.is_none()) return {};
    if (py::isinstance<py::int_>(zoom)) return std::to_string(py::cast<long>(zoom));
    return py::cast<std::string>(zoom);
}

optics::Lens load(const std::string& path, const py::object& zoom) {
    DeferredReporter reporter;
    optics::Lens lens = optics::loadLensAt(optics::findLensFile(path), zoomText(zoom), &reporter);
    reporter.flush();
    return lens;
}

py::object firstOrder(const optics::Lens& lens, double lambdaNm) {
    DeferredReporter reporter;
    const std::string label = lens.isZoom() ? lens.zoomLabels[lens.activeZoom] : std::string();
    py::dict d = fromJson(report::positionJson(report::positionReport(lens, lambdaNm, label, &reporter)));
    d["wavelength_nm"] = lambdaNm;
    reporter.flush();
    return d;
}

py::object info(const optics::Lens& lens, double lambdaNm) {
    DeferredReporter reporter;
    py::object d =
        fromJson(report::lensInfoJson(lens, lambdaNm, report::positionReports(lens, lambdaNm, "", &reporter)));
    reporter.flush();
    return d;
}

} // namespace

void bindLens(py::module_& m) {
    py::class_<optics::Lens, std::shared_ptr<optics::Lens>>(m, "Lens", R"(A lens prescription (.lens, .zmx or .dat).

Lengths are in millimetres, wavelengths in nanometres, angles in degrees.)")
        .def_static("load", &load, "path"_a, "zoom"_a = py::none(),
                    R"(Reads a lens file; the format follows the extension (.lens, .zmx, .dat). path: a
file, or the name of an installed lens ("double-gauss-50mm-f2"; docs/install.md).

zoom: a zoom position's label (str) or 1-based index (int); None keeps the file's first position.
Raises InputError with file:line:column for a malformed file. Notes and warnings about the file
go to the "fourierflare" logger.)")
        .def_property_readonly("name", [](const optics::Lens& l) { return l.name; })
        .def_property_readonly("file", [](const optics::Lens& l) { return l.file; })
        .def_property_readonly("format", [](const optics::Lens& l) { return l.format; })
        .def_property_readonly("content_hash", [](const optics::Lens& l) { return l.contentHash; })
        .def_property_readonly(
            "zoom_positions", [](const optics::Lens& l) { return l.zoomLabels; },
            "The zoom positions' labels (empty for a prime lens).")
        .def_property_readonly(
            "aperture_blades", [](const optics::Lens& l) { return l.apertureBlades; }, "Iris blades (0: a round iris).")
        .def_property_readonly(
            "surfaces", [](const optics::Lens& l) { return fromJson(report::surfacesJson(l, lines::d)); },
            R"(The surfaces as a list of dicts, front to back: index (1-based), radius_mm (None: flat),
conic, asphere, thickness_mm (per zoom position for a zoom gap), medium {glass, nd, vd, n (at the
d line), and for a graded medium gradient {radial: coefficients of r^2, r^4, ...; axial: of z, z^2,
... (mm^-k, at the d line)}}, semi_aperture_mm, coating, stop, shape. The same fields as
`fourierflare lens info --json`.)")
        .def("first_order", &firstOrder, "wavelength_nm"_a = lines::d,
             R"(First-order optics at wavelength_nm (default the d line, 587.56 nm) as a dict: efl_mm,
bfd_mm, ffd_mm, entrance/exit pupil position (z, mm from the first / last vertex) and diameter,
f_number, stop_semi_aperture_mm, image_distance_mm, total_track_mm, real_ray_efl_mm (a real ray's
check of the EFL), reflecting_interfaces, two_bounce_ghosts; None for what an afocal lens lacks.)")
        .def("info", &info, "wavelength_nm"_a = lines::d,
             "The whole report of `fourierflare lens info --json` (every zoom position) as a dict.")
        .def("__repr__", [](const optics::Lens& l) {
            return "<fourierflare.Lens '" + l.name + "' from '" + l.file + "', " + std::to_string(l.surfaces.size()) +
                   " surfaces>";
        });
}

} // namespace ff::python
