#include "report/lens_report.h"

#include "core/error.h"
#include "core/text.h"
#include "optics/real_ray.h"
#include "optics/zoom.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace ff::report {

using optics::Lens;
using optics::Surface;
using text::fixed;

namespace {

std::string mediumText(const optics::Medium& m) {
    if (!m.glass.empty()) return m.glass;
    if (m.isAir()) return "air";
    return "nd " + fixed(m.nd, 5) + (m.vd > 0.0 ? " Vd " + fixed(m.vd, 2) : std::string(" Vd 0"));
}

// A graded medium's index at lambdaNm as a formula: "n = n0 - 0.0923965 r^2 + 0.004 z" (mm).
std::string gradientText(const optics::Medium& m, double lambdaNm) {
    std::string out = "n = " + fixed(m.index(lambdaNm), 5);
    auto terms = [&](const std::vector<optics::GradientTerm>& ts, const char* var, int step) {
        for (std::size_t k = 0; k < ts.size(); ++k) {
            const double c = ts[k].at(lambdaNm);
            if (c == 0.0) continue;
            const int power = static_cast<int>(k + 1) * step;
            char coefficient[32];
            std::snprintf(coefficient, sizeof coefficient, "%.6g", std::abs(c));
            out += (c < 0.0 ? " - " : " + ") + std::string(coefficient) + " " + var +
                   (power > 1 ? "^" + std::to_string(power) : std::string());
        }
    };
    terms(m.gradient->radial, "r", 2);
    terms(m.gradient->axial, "z", 1);
    return out;
}

std::string thicknessText(const Lens& lens, std::size_t i) {
    if (i + 1 == lens.surfaces.size() && lens.imageDistanceAuto) return "auto";
    if (i < lens.zoomGaps.size() && !lens.zoomGaps[i].empty()) {
        std::string s;
        for (std::size_t k = 0; k < lens.zoomGaps[i].size(); ++k) {
            if (k) s += '/';
            s += fixed(lens.zoomGaps[i][k], 3);
        }
        return s;
    }
    return fixed(lens.surfaces[i].thickness, 4);
}

std::string pupilZText(double z, const char* reference) {
    if (!std::isfinite(z)) return "at infinity (telecentric)";
    char buf[128];
    std::snprintf(buf, sizeof buf, "%.3f mm %s %s", std::abs(z), z >= 0.0 ? "behind" : "in front of", reference);
    return buf;
}

std::string row(const char* label, const std::string& value) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "  %-26s", label);
    return std::string(buf) + value + "\n";
}

} // namespace

namespace {

// One section's focal rows: the EFL, BFD (and FFD), or an afocal lens's angular magnification; then
// the entrance pupil.
void focalRows(std::ostringstream& o, const optics::FirstOrder& f, bool withFfd) {
    if (f.afocal) {
        o << row("effective focal length",
                 "none: afocal (zero power), angular magnification " + fixed(f.angularMagnification, 4));
    } else {
        o << row("effective focal length", fixed(f.efl, 3) + " mm");
        o << row("back focal distance", fixed(f.bfd, 3) + " mm (last vertex to paraxial focus)");
        if (withFfd) o << row("front focal distance", fixed(f.ffd, 3) + " mm (front focal point to first vertex)");
    }
    o << row("entrance pupil", pupilZText(f.entrancePupilZ, "the first vertex") + ", diameter " +
                                   fixed(f.entrancePupilDiameter, 3) + " mm");
}

// An anamorphic lens's x-z section: its focal data, pupils and real-ray check, and the squeeze.
void sectionXText(std::ostringstream& o, const PositionReport& p) {
    const optics::FirstOrder& f = *p.sectionX;
    o << "  the x-z section:\n";
    focalRows(o, f, false);
    o << row("exit pupil", pupilZText(f.exitPupilZ, "the last vertex"));
    if (!f.afocal) o << row("f-number", "f/" + fixed(f.fNumber, 2));
    o << row("real-ray focal length", std::isfinite(p.realRayEflX)
                                          ? fixed(p.realRayEflX, 3) + " mm (ray at 1e-4 of the pupil radius)"
                                          : "not checked: " + p.realRayProblemX);
    o << row("squeeze", std::isfinite(p.squeeze) ? fixed(p.squeeze, 4) + " (EFL y-z / EFL x-z)"
                                                 : std::string("none: a section is afocal"));
}

} // namespace

std::string lensInfoText(const Lens& lens, double lambdaNm, const std::vector<PositionReport>& positions) {
    std::ostringstream o;
    o << (lens.name.empty() ? std::string("(unnamed lens)") : lens.name) << "\n";
    o << "  file: " << lens.file << " (" << lens.format << " format)\n";
    if (!lens.source.empty()) o << "  source: " << lens.source << "\n";
    if (!lens.patent.empty()) o << "  patent: " << lens.patent << "\n";
    if (lens.nominalFocalLength)
        o << "  nominal focal length (header): "
          << (std::isinf(*lens.nominalFocalLength) ? std::string("inf (afocal)")
                                                   : text::roundTrip(*lens.nominalFocalLength) + " mm")
          << "\n";
    if (lens.fNumber) o << "  working f-number (header): f/" << text::roundTrip(*lens.fNumber) << "\n";
    if (lens.sensorMm)
        o << "  sensor: " << text::roundTrip(lens.sensorMm->first) << " x " << text::roundTrip(lens.sensorMm->second)
          << " mm\n";
    o << "  iris: "
      << (lens.apertureBlades ? std::to_string(lens.apertureBlades) + " blades" : std::string("circular"));
    if (lens.bladeRotationDeg != 0.0) o << ", rotated " << text::roundTrip(lens.bladeRotationDeg) << " deg";
    o << "\n";
    if (lens.isZoom()) o << "  zoom positions: " << text::join(lens.zoomLabels) << "\n";
    o << "\n";

    char buf[256];
    std::snprintf(buf, sizeof buf, "  %3s %12s %21s  %-22s %9s %9s  %-12s %s\n", "#", "radius", "thickness",
                  "medium after", ("n@" + fixed(lambdaNm, 1)).c_str(), "semi-ap", "coating", "notes");
    o << buf;
    for (std::size_t i = 0; i < lens.surfaces.size(); ++i) {
        const Surface& s = lens.surfaces[i];
        std::string radius = s.radius == 0.0 ? "flat" : fixed(s.radius, 4);
        std::string extra;
        if (s.stop) extra += " STOP";
        if (s.conic != 0.0) extra += " k=" + text::roundTrip(s.conic);
        if (s.isAspheric()) extra += " asphere(" + std::to_string(s.asphere.size()) + " terms)";
        if (s.shape == optics::SurfaceShape::Biconic)
            extra += " biconic, x-z radius " + (s.radiusX == 0.0 ? std::string("flat") : fixed(s.radiusX, 4)) +
                     (s.conicX != 0.0 ? " k=" + text::roundTrip(s.conicX) : std::string());
        else if (!s.rotationallySymmetric())
            extra += std::string(" ") + optics::toString(s.shape);
        if (s.medium.gradient) extra += " graded index (below)";
        std::snprintf(buf, sizeof buf, "  %3zu %12s %21s  %-22s %9.5f %9.4f  %-12s%s\n", i + 1, radius.c_str(),
                      thicknessText(lens, i).c_str(), mediumText(s.medium).c_str(), s.medium.index(lambdaNm),
                      s.semiAperture, lens.coatingOf(i).str().c_str(), extra.c_str());
        o << buf;
    }

    for (std::size_t i = 0; i < lens.surfaces.size(); ++i)
        if (lens.surfaces[i].medium.gradient)
            o << "  graded index after surface " << i + 1 << " at " << fixed(lambdaNm, 1)
              << " nm (r from the axis, z from the vertex, mm): " << gradientText(lens.surfaces[i].medium, lambdaNm)
              << "\n";

    for (const PositionReport& p : positions) {
        const optics::FirstOrder& f = p.firstOrder;
        o << "\nFirst-order optics at " << fixed(lambdaNm, 2) << " nm";
        if (!p.label.empty()) o << ", zoom position " << p.label;
        if (p.sectionX) o << ", the y-z section (anamorphic lens; the x-z section below)";
        o << ":\n";
        focalRows(o, f, true);
        o << row("exit pupil",
                 pupilZText(f.exitPupilZ, "the last vertex") +
                     (std::isfinite(f.exitPupilDiameter) ? ", diameter " + fixed(f.exitPupilDiameter, 3) + " mm"
                                                         : std::string()));
        if (!f.afocal) o << row("f-number", "f/" + fixed(f.fNumber, 2));
        o << row("aperture stop",
                 "surface " + std::to_string(lens.stopIndex() + 1) +
                     (lens.stopInferred ? " (no stop row: the surface that limits the axial beam)" : ""));
        o << row("stop semi-aperture", fixed(f.stopSemiAperture, 3) + " mm");
        if (f.afocal)
            o << row("sensor distance", fixed(f.imageDistance, 3) + " mm (last vertex to sensor)");
        else
            o << row("sensor distance", fixed(f.imageDistance, 3) + " mm (last vertex to sensor; defocus " +
                                            fixed(f.imageDistance - f.bfd, 3) + " mm)");
        o << row("total track", fixed(f.totalTrack, 3) + " mm (first vertex to sensor)");
        o << row("real-ray focal length", std::isfinite(p.realRayEfl)
                                              ? fixed(p.realRayEfl, 3) + " mm (ray at 1e-4 of the pupil radius)"
                                              : "not checked: " + p.realRayProblem);
        o << row("reflecting interfaces", std::to_string(f.reflectingInterfaces));
        o << row("two-bounce ghosts", std::to_string(f.ghostCount));
        if (p.sectionX) sectionXText(o, p);
    }
    return o.str();
}

namespace {

// The real-ray focal length of one section (a ray at 1e-4 of its entrance pupil's radius), or NaN
// with why not: a check of the paraxial data, not part of them, so the report goes on without it.
double realRayCheck(const Lens& lens, double lambdaNm, const optics::FirstOrder& f, optics::Section section,
                    std::string& problem, Reporter* reporter) {
    if (f.afocal) {
        problem = "the lens is afocal: a ray parallel to the axis leaves parallel";
        return std::numeric_limits<double>::quiet_NaN();
    }
    try {
        return optics::realRayEfl(lens, lambdaNm, 1e-4 * 0.5 * f.entrancePupilDiameter, section);
    } catch (const Error& e) {
        problem = e.message();
        if (reporter) reporter->note({lens.file, 0, 0}, "the real-ray focal length could not be checked: " + problem);
        return std::numeric_limits<double>::quiet_NaN();
    }
}

} // namespace

PositionReport positionReport(const Lens& lens, double lambdaNm, const std::string& label, Reporter* reporter) {
    PositionReport p;
    p.label = label;
    const bool anamorphic = !lens.rotationallySymmetric();
    p.firstOrder = optics::analyzeFirstOrder(anamorphic ? optics::sectionOf(lens, optics::Section::Y) : lens, lambdaNm,
                                             /*allowAfocal=*/true);
    p.realRayEfl = realRayCheck(lens, lambdaNm, p.firstOrder, optics::Section::Y, p.realRayProblem, reporter);
    if (anamorphic) {
        p.sectionX = optics::analyzeFirstOrder(optics::sectionOf(lens, optics::Section::X), lambdaNm, true);
        p.realRayEflX = realRayCheck(lens, lambdaNm, *p.sectionX, optics::Section::X, p.realRayProblemX, reporter);
        p.squeeze = p.firstOrder.afocal || p.sectionX->afocal ? std::numeric_limits<double>::quiet_NaN()
                                                              : p.firstOrder.efl / p.sectionX->efl;
    }
    return p;
}

std::vector<PositionReport> positionReports(const Lens& lens, double lambdaNm, const std::string& zoom,
                                            Reporter* reporter) {
    std::vector<std::size_t> which;
    if (!zoom.empty())
        which.push_back(optics::findZoomPosition(lens, zoom));
    else
        for (std::size_t k = 0; k < lens.zoomCount(); ++k) which.push_back(k);
    std::vector<PositionReport> positions;
    for (std::size_t k : which)
        positions.push_back(
            positionReport(optics::atZoom(lens, k), lambdaNm, lens.isZoom() ? lens.zoomLabels[k] : "", reporter));
    return positions;
}

nlohmann::json positionJson(const PositionReport& p) {
    using nlohmann::json;
    auto finiteOrNull = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    const optics::FirstOrder& f = p.firstOrder;
    json out = {{"label", p.label},
                {"efl_mm", finiteOrNull(f.efl)},
                {"bfd_mm", finiteOrNull(f.bfd)},
                {"ffd_mm", finiteOrNull(f.ffd)},
                {"entrance_pupil_z_mm", f.entrancePupilZ},
                {"entrance_pupil_diameter_mm", f.entrancePupilDiameter},
                {"exit_pupil_z_mm", finiteOrNull(f.exitPupilZ)},
                {"exit_pupil_diameter_mm", finiteOrNull(f.exitPupilDiameter)},
                {"f_number", finiteOrNull(f.fNumber)},
                {"afocal", f.afocal},
                {"angular_magnification", f.afocal ? json(f.angularMagnification) : json(nullptr)},
                {"stop_semi_aperture_mm", f.stopSemiAperture},
                {"image_distance_mm", f.imageDistance},
                {"total_track_mm", f.totalTrack},
                {"real_ray_efl_mm", finiteOrNull(p.realRayEfl)},
                {"real_ray_problem", p.realRayProblem},
                {"reflecting_interfaces", f.reflectingInterfaces},
                {"two_bounce_ghosts", f.ghostCount}};
    if (p.sectionX) {
        // An anamorphic lens: the keys above are its y-z section's.
        const optics::FirstOrder& x = *p.sectionX;
        out["section_x"] = {{"efl_mm", finiteOrNull(x.efl)},
                            {"bfd_mm", finiteOrNull(x.bfd)},
                            {"ffd_mm", finiteOrNull(x.ffd)},
                            {"entrance_pupil_z_mm", x.entrancePupilZ},
                            {"entrance_pupil_diameter_mm", x.entrancePupilDiameter},
                            {"exit_pupil_z_mm", finiteOrNull(x.exitPupilZ)},
                            {"f_number", finiteOrNull(x.fNumber)},
                            {"afocal", x.afocal},
                            {"real_ray_efl_mm", finiteOrNull(p.realRayEflX)},
                            {"real_ray_problem", p.realRayProblemX}};
        out["squeeze"] = finiteOrNull(p.squeeze);
    }
    return out;
}

nlohmann::json surfacesJson(const Lens& lens, double lambdaNm) {
    using nlohmann::json;
    json surfaces = json::array();
    for (std::size_t i = 0; i < lens.surfaces.size(); ++i) {
        const Surface& s = lens.surfaces[i];
        json js;
        js["index"] = i + 1;
        js["radius_mm"] = s.radius == 0.0 ? json(nullptr) : json(s.radius);
        js["conic"] = s.conic;
        js["asphere"] = s.asphere;
        if (i < lens.zoomGaps.size() && !lens.zoomGaps[i].empty())
            js["thickness_mm"] = lens.zoomGaps[i];
        else
            js["thickness_mm"] = s.thickness;
        js["medium"] = {{"glass", s.medium.glass.empty() ? json(nullptr) : json(s.medium.glass)},
                        {"nd", s.medium.nd},
                        {"vd", s.medium.vd},
                        {"n", s.medium.index(lambdaNm)}};
        if (s.medium.gradient) {
            // Each coefficient at lambdaNm, of r^2, r^4, ... and of z, z^2, ... (mm^-k).
            auto at = [&](const std::vector<optics::GradientTerm>& ts) {
                json a = json::array();
                for (const auto& t : ts) a.push_back(t.at(lambdaNm));
                return a;
            };
            js["medium"]["gradient"] = {{"radial", at(s.medium.gradient->radial)},
                                        {"axial", at(s.medium.gradient->axial)}};
        }
        js["semi_aperture_mm"] = s.semiAperture;
        js["coating"] = lens.coatingOf(i).str();
        js["stop"] = s.stop;
        js["shape"] = optics::toString(s.shape);
        if (!s.rotationallySymmetric()) {
            // The sections' radii (null: flat) and conics.
            const auto radius = [](double c) { return c == 0.0 ? json(nullptr) : json(1.0 / c); };
            js["radius_x_mm"] = radius(s.curvatureX());
            js["radius_y_mm"] = radius(s.curvatureY());
            js["conic_x"] = s.conicOfX();
            js["conic_y"] = s.conicOfY();
        }
        surfaces.push_back(js);
    }
    return surfaces;
}

nlohmann::json lensInfoJson(const Lens& lens, double lambdaNm, const std::vector<PositionReport>& positions) {
    using nlohmann::json;
    auto optional = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
    json j;
    j["name"] = lens.name;
    j["file"] = lens.file;
    j["format"] = lens.format;
    j["content_hash"] = lens.contentHash;
    j["source"] = lens.source;
    j["patent"] = lens.patent;
    j["nominal_focal_length_mm"] = optional(lens.nominalFocalLength); // null where absent or afocal (inf)
    j["stop_surface"] = lens.stopIndex() + 1;
    j["stop_inferred"] = lens.stopInferred;
    j["afocal_header"] = lens.nominalFocalLength && std::isinf(*lens.nominalFocalLength);
    j["f_number_header"] = optional(lens.fNumber);
    j["sensor_mm"] = lens.sensorMm ? json::array({lens.sensorMm->first, lens.sensorMm->second}) : json(nullptr);
    j["aperture_blades"] = lens.apertureBlades;
    j["blade_rotation_deg"] = lens.bladeRotationDeg;
    j["wavelength_nm"] = lambdaNm;
    j["zoom_positions"] = lens.zoomLabels;
    j["surfaces"] = surfacesJson(lens, lambdaNm);
    j["image_distance_auto"] = lens.imageDistanceAuto;
    json pos = json::array();
    for (const PositionReport& p : positions) pos.push_back(positionJson(p));
    j["first_order"] = pos;
    return j;
}

} // namespace ff::report
