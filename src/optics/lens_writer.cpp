#include "optics/lens_writer.h"

#include "core/text.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

namespace ff::optics {

namespace {

std::string num(double v) {
    return text::roundTrip(v);
}

std::string pad(const std::string& s, std::size_t width) {
    return s.size() >= width ? s + " " : s + std::string(width - s.size(), ' ');
}

} // namespace

std::string writeLensText(const Lens& lens) {
    std::ostringstream o;
    o << "# " << (lens.name.empty() ? std::string("Lens") : lens.name) << "\n";
    if (!lens.file.empty()) o << "# Converted by fourierflare from " << lens.file << " (" << lens.format << ")\n";
    o << "\n";
    if (!lens.name.empty()) o << "name: " << lens.name << "\n";
    if (!lens.source.empty()) o << "source: " << lens.source << "\n";
    if (!lens.patent.empty()) o << "patent: " << lens.patent << "\n";
    if (lens.nominalFocalLength)
        o << "focal_length: "
          << (std::isinf(*lens.nominalFocalLength) ? std::string("inf") : num(*lens.nominalFocalLength)) << "\n";
    if (lens.fNumber) o << "f_number: " << num(*lens.fNumber) << "\n";
    if (lens.sensorMm) o << "sensor: " << num(lens.sensorMm->first) << "x" << num(lens.sensorMm->second) << "\n";
    if (lens.apertureBlades) o << "aperture_blades: " << lens.apertureBlades << "\n";
    if (lens.bladeRotationDeg != 0.0) o << "blade_rotation: " << num(lens.bladeRotationDeg) << "\n";
    if (lens.defaultCoating) o << "coating: " << lens.defaultCoating->str() << "\n";
    if (lens.isZoom()) o << "zoom_positions: " << text::join(lens.zoomLabels, " ") << "\n";
    o << "\nsurfaces:\n# radius       thickness      ior       abbe     semi_ap   coating  options\n";

    for (std::size_t i = 0; i < lens.surfaces.size(); ++i) {
        const Surface& s = lens.surfaces[i];
        std::string row = "  ";
        row += pad(s.flatStopRow ? std::string("stop") : num(s.radius), 14);
        std::string thick;
        if (i + 1 == lens.surfaces.size() && lens.imageDistanceAuto) {
            thick = "auto";
        } else if (i < lens.zoomGaps.size() && !lens.zoomGaps[i].empty()) {
            for (std::size_t k = 0; k < lens.zoomGaps[i].size(); ++k) {
                if (k) thick += ',';
                thick += num(lens.zoomGaps[i][k]);
            }
        } else {
            thick = num(s.thickness);
        }
        row += pad(thick, 15);
        if (!s.medium.glass.empty())
            row += pad(s.medium.glass, 19);
        else
            row += pad(num(s.medium.nd), 10) + pad(num(s.medium.vd), 9);
        row += pad(num(s.semiAperture), 10) + pad(std::to_string(s.coatingLayers), 9);
        if (s.shape == SurfaceShape::Biconic) {
            row += "biconic=" + num(s.radiusX) + (s.conicX != 0.0 ? "," + num(s.conicX) : std::string()) + " ";
        } else if (s.shape != SurfaceShape::Spherical) {
            row += std::string(toString(s.shape)) + " ";
            if (s.radiusY != 0.0) row += num(s.radiusY) + " ";
        }
        if (s.stop && !s.flatStopRow) row += "stop ";
        if (s.conic != 0.0) row += "conic=" + num(s.conic) + " ";
        if (!s.asphere.empty()) {
            row += "asph=";
            for (std::size_t k = 0; k < s.asphere.size(); ++k) {
                if (k) row += ',';
                row += num(s.asphere[k]);
            }
            row += " ";
        }
        if (s.coating) row += "coating=" + s.coating->token() + " ";
        if (s.medium.gradient)
            for (const auto& [key, terms] :
                 {std::pair{"grin_r=", &s.medium.gradient->radial}, std::pair{"grin_z=", &s.medium.gradient->axial}}) {
                if (terms->empty()) continue;
                row += key;
                for (std::size_t k = 0; k < terms->size(); ++k)
                    row += (k ? "," : "") + num((*terms)[k].atD) + ":" + num((*terms)[k].dispersion);
                row += " ";
            }
        while (!row.empty() && row.back() == ' ') row.pop_back();
        o << row << "\n";
    }
    return o.str();
}

} // namespace ff::optics
