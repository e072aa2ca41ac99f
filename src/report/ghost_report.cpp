#include "report/ghost_report.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace ff::report {

trace::GhostAnalysisOptions GhostQuery::options() const {
    if (!std::isfinite(angleDeg) || !std::isfinite(azimuthDeg))
        throw Error(ErrorKind::Usage, "the field angle and azimuth must be finite numbers of degrees");
    if (wavelengthsNm.empty()) throw Error(ErrorKind::Usage, "give at least one wavelength");
    for (double l : wavelengthsNm)
        if (!(l >= 300.0 && l <= 2000.0))
            throw Error(ErrorKind::Usage, "wavelengths must lie in 300..2000 nm, got " + text::roundTrip(l));
    if (grid < 2 || grid > 1024)
        throw Error(ErrorKind::Usage, "the pupil grid must have 2..1024 rays per side, got " + std::to_string(grid));
    trace::GhostAnalysisOptions a;
    a.field = {degToRad(angleDeg), degToRad(azimuthDeg)};
    a.wavelengthsNm = wavelengthsNm;
    a.grid = grid;
    a.sampling = trace::samplingNamed(sampling);
    a.sensor = trace::sensorPlaneNamed(sensor);
    a.coating = trace::coatingNamed(coating);
    return a;
}

nlohmann::json pathJson(const trace::PathStats& p) {
    auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    nlohmann::json j = {{"path", p.label()},
                        {"launched", p.launched},
                        {"surviving", p.surviving},
                        {"blocked", p.blocked},
                        {"surviving_fraction", p.launched ? double(p.surviving) / double(p.launched) : 0.0},
                        {"relative_energy", p.relativeEnergy},
                        {"energy_per_launched_ray", p.energyPerRay},
                        {"centroid_mm", {p.centroidX, p.centroidY}},
                        {"rms_radius_mm", p.rmsRadius},
                        {"axial_ratio", num(p.axialRatio)},
                        {"on_sensor_share", p.onSensor}};
    if (p.ghost) j["surfaces"] = {p.ghost->first + 1, p.ghost->second + 1};
    return j;
}

nlohmann::json ghostReportJson(const optics::Lens& lens, const GhostQuery& q, const trace::GhostReport& r,
                               std::size_t shown) {
    const std::size_t nGhosts = r.wavelengths.empty() ? 0 : r.wavelengths[0].ghosts.size();
    nlohmann::json j = {{"lens", lens.name},
                        {"file", lens.file},
                        {"field_angle_deg", q.angleDeg},
                        {"azimuth_deg", q.azimuthDeg},
                        {"sampling", q.sampling},
                        {"grid", q.grid},
                        {"coating", q.coating},
                        {"sensor", q.sensor},
                        {"sensor_z_mm", r.sensorZ},
                        {"sensor_size_mm", {r.sensorSizeMm.first, r.sensorSizeMm.second}},
                        {"reflecting_interfaces", r.reflectingInterfaces},
                        {"ghost_count", nGhosts}};
    nlohmann::json wl = nlohmann::json::array();
    for (const auto& w : r.wavelengths) {
        nlohmann::json ghosts = nlohmann::json::array();
        for (std::size_t i = 0; i < std::min(shown, w.ghosts.size()); ++i) ghosts.push_back(pathJson(w.ghosts[i]));
        wl.push_back({{"wavelength_nm", w.lambdaNm},
                      {"direct", pathJson(w.direct)},
                      {"ghosts", ghosts},
                      {"total_ghost_relative_energy", w.totalGhostRelative}});
    }
    j["wavelengths"] = wl;
    return j;
}

} // namespace ff::report
