#include "ghosts/table_json.h"

#include "core/error.h"
#include "core/json_integer.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace ff::ghosts {

using nlohmann::json;

namespace {

constexpr const char* kSchema = "fourierflare.ghost-table";

template <typename F>
json series(const std::vector<TableEntry>& row, F f) {
    json a = json::array();
    for (const TableEntry& e : row) a.push_back(f(e));
    return a;
}

std::vector<double> numbers(const json& j, const char* key, std::size_t expected, const std::string& source) {
    const json& a = j.at(key);
    if (!a.is_array() || a.size() != expected)
        throw Error(ErrorKind::Input, SourceLocation{source},
                    std::string("ghost table field '") + key + "' has the wrong length");
    return a.get<std::vector<double>>();
}

// Field angles: at least one, finite, increasing from 0.
std::vector<double> angles(const json& j, const std::string& source) {
    const auto a = j.at("field_angles_deg").get<std::vector<double>>();
    if (a.empty() || a.front() != 0.0)
        throw Error(ErrorKind::Input, SourceLocation{source}, "ghost table field angles do not start at 0");
    for (std::size_t i = 1; i < a.size(); ++i)
        if (!(a[i] > a[i - 1]) || !std::isfinite(a[i]))
            throw Error(ErrorKind::Input, SourceLocation{source}, "ghost table field angles are not increasing");
    return a;
}

} // namespace

std::string tableToJson(const GhostTable& t, bool compact) {
    json j;
    j["schema"] = kSchema;
    j["schema_version"] = t.schemaVersion;
    j["lens"] = {{"name", t.lensName},
                 {"file", t.lensFile},
                 {"hash", t.lensHash},
                 {"efl_mm", t.efl},
                 {"aperture_blades", t.apertureBlades},
                 {"blade_rotation_deg", t.bladeRotationDeg}};
    j["settings_key"] = t.settingsKey;
    j["sensor"] = {{"z_mm", t.sensorZ}, {"width_mm", t.sensorSizeMm.first}, {"height_mm", t.sensorSizeMm.second}};
    j["convention"] =
        "source at azimuth 0, its direct image at +y on the sensor; a light at image position p (mm from the "
        "optical centre) has its ghost centred at m * p, rotated with the light; widths are radial (along p) "
        "and tangential; flux relative to the direct image of the same source at the same wavelength";
    j["wavelengths_nm"] = t.wavelengthsNm;
    j["field_angles_deg"] = t.anglesDeg;
    j["direct_image_height_mm"] = t.directY;
    json ghosts = json::array();
    for (std::size_t g = 0; g < t.ghosts.size(); ++g) {
        const TableGhost& tg = t.ghosts[g];
        json per = json::array();
        for (std::size_t w = 0; w < tg.entries.size(); ++w) {
            const auto& row = tg.entries[w];
            json m = json::array();
            for (double a : tg.anglesDeg) m.push_back(t.magnification(g, w, a));
            per.push_back(
                {{"centroid_mm", series(row, [](const TableEntry& e) { return e.centroidY; })},
                 {"magnification", m},
                 {"sigma_radial_mm", series(row, [](const TableEntry& e) { return e.sigmaR; })},
                 {"sigma_tangential_mm", series(row, [](const TableEntry& e) { return e.sigmaT; })},
                 {"relative_flux", series(row, [](const TableEntry& e) { return e.flux; })},
                 {"surviving_fraction", series(row, [](const TableEntry& e) { return e.surviving; })},
                 {"gaussian",
                  {{"sigma_radial_mm", series(row, [](const TableEntry& e) { return e.gaussian.widthR; })},
                   {"sigma_tangential_mm", series(row, [](const TableEntry& e) { return e.gaussian.widthT; })},
                   {"peak_per_mm2", series(row, [](const TableEntry& e) { return e.gaussian.peak; })},
                   {"fit_error", series(row, [](const TableEntry& e) { return e.gaussian.error; })}}},
                 {"cos2",
                  {{"w_radial_mm", series(row, [](const TableEntry& e) { return e.cos2.widthR; })},
                   {"w_tangential_mm", series(row, [](const TableEntry& e) { return e.cos2.widthT; })},
                   {"peak_per_mm2", series(row, [](const TableEntry& e) { return e.cos2.peak; })},
                   {"fit_error", series(row, [](const TableEntry& e) { return e.cos2.error; })}}}});
        }
        ghosts.push_back({{"id", "g_" + std::to_string(tg.pair.first + 1) + "_" + std::to_string(tg.pair.second + 1)},
                          {"label", tg.pair.label()},
                          {"surfaces", {tg.pair.first + 1, tg.pair.second + 1}},
                          {"field_angles_deg", tg.anglesDeg},
                          {"wavelengths", per}});
    }
    j["ghosts"] = ghosts;
    return compact ? j.dump() : j.dump(1);
}

GhostTable tableFromJson(const std::string& text, const std::string& source) {
    const SourceLocation where{source};
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {
        throw Error(ErrorKind::Input, where, std::string("not a ghost table: ") + e.what());
    }
    try {
        if (j.value("schema", "") != kSchema)
            throw Error(ErrorKind::Input, where, "not a FourierFlare ghost table (schema)");
        GhostTable t;
        t.schemaVersion = jsonInteger<int>(j.at("schema_version"));
        if (t.schemaVersion != GhostTable{}.schemaVersion)
            throw Error(ErrorKind::Input, where,
                        "ghost table schema version " + std::to_string(t.schemaVersion) + " is not supported");
        const json& lens = j.at("lens");
        t.lensName = lens.at("name").get<std::string>();
        t.lensFile = lens.at("file").get<std::string>();
        t.lensHash = lens.at("hash").get<std::string>();
        t.efl = lens.at("efl_mm").get<double>();
        t.apertureBlades = jsonInteger<int>(lens.at("aperture_blades"));
        t.bladeRotationDeg = lens.at("blade_rotation_deg").get<double>();
        t.settingsKey = j.at("settings_key").get<std::string>();
        t.sensorZ = j.at("sensor").at("z_mm").get<double>();
        t.sensorSizeMm = {j.at("sensor").at("width_mm").get<double>(), j.at("sensor").at("height_mm").get<double>()};
        t.wavelengthsNm = j.at("wavelengths_nm").get<std::vector<double>>();
        t.anglesDeg = angles(j, source);
        t.buildSeconds = j.value("build_seconds", 0.0); // written up to 0.1.0's tables; timing, not data
        const std::size_t nW = t.wavelengthsNm.size();
        if (nW == 0) throw Error(ErrorKind::Input, where, "ghost table without wavelengths");
        t.directY = j.at("direct_image_height_mm").get<std::vector<std::vector<double>>>();
        if (t.directY.size() != nW)
            throw Error(ErrorKind::Input, where, "ghost table direct image heights do not match its wavelengths");
        for (const auto& row : t.directY)
            if (row.size() != t.anglesDeg.size())
                throw Error(ErrorKind::Input, where, "ghost table direct image heights do not match its angles");
        for (const json& g : j.at("ghosts")) {
            TableGhost tg;
            const auto s = jsonIntegers<std::size_t>(g.at("surfaces"));
            if (s.size() != 2 || s[0] < 1 || s[1] < 1)
                throw Error(ErrorKind::Input, where, "ghost table entry with bad surfaces");
            tg.pair = {s[0] - 1, s[1] - 1};
            tg.anglesDeg = angles(g, source);
            const std::size_t nA = tg.anglesDeg.size();
            const json& per = g.at("wavelengths");
            if (per.size() != nW)
                throw Error(ErrorKind::Input, where, "ghost table entry does not match its wavelengths");
            for (const json& w : per) {
                const auto cy = numbers(w, "centroid_mm", nA, source), sr = numbers(w, "sigma_radial_mm", nA, source),
                           st = numbers(w, "sigma_tangential_mm", nA, source),
                           fl = numbers(w, "relative_flux", nA, source),
                           sv = numbers(w, "surviving_fraction", nA, source);
                const json &gj = w.at("gaussian"), &cj = w.at("cos2");
                const auto gr = numbers(gj, "sigma_radial_mm", nA, source),
                           gt = numbers(gj, "sigma_tangential_mm", nA, source),
                           gp = numbers(gj, "peak_per_mm2", nA, source), ge = numbers(gj, "fit_error", nA, source);
                const auto cr = numbers(cj, "w_radial_mm", nA, source), ct = numbers(cj, "w_tangential_mm", nA, source),
                           cp = numbers(cj, "peak_per_mm2", nA, source), ce = numbers(cj, "fit_error", nA, source);
                std::vector<TableEntry> row(nA);
                for (std::size_t a = 0; a < nA; ++a)
                    row[a] = {
                        cy[a], sr[a], st[a], fl[a], sv[a], {gr[a], gt[a], gp[a], ge[a]}, {cr[a], ct[a], cp[a], ce[a]}};
                tg.entries.push_back(std::move(row));
            }
            t.ghosts.push_back(std::move(tg));
        }
        return t;
    } catch (const json::exception& e) {
        throw Error(ErrorKind::Input, where, std::string("malformed ghost table: ") + e.what());
    }
}

} // namespace ff::ghosts
