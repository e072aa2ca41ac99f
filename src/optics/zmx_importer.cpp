#include "optics/zmx_importer.h"

#include "core/text.h"
#include "core/units.h"
#include "optics/glass_catalog.h"
#include "optics/lens_parser.h"
#include "optics/lens_validation.h"
#include "optics/paraxial.h"

#include <cmath>
#include <map>

namespace ff::optics {

namespace {

void appendUtf8(std::string& out, char32_t cp) {
    if (cp < 0x80) {
        out += static_cast<char>(cp);
    } else if (cp < 0x800) {
        out += static_cast<char>(0xC0 | (cp >> 6));
        out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
        out += static_cast<char>(0xE0 | (cp >> 12));
        out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
        out += static_cast<char>(0xF0 | (cp >> 18));
        out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
        out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (cp & 0x3F));
    }
}

std::string fromUtf16(std::string_view b, bool littleEndian, const std::string& fileName) {
    if (b.size() % 2 != 0) throwInputError({fileName}, "UTF-16 file with an odd number of bytes (truncated?)");
    std::string out;
    out.reserve(b.size() / 2);
    auto unit = [&](std::size_t i) {
        const auto lo = static_cast<unsigned char>(b[i + (littleEndian ? 0 : 1)]);
        const auto hi = static_cast<unsigned char>(b[i + (littleEndian ? 1 : 0)]);
        return static_cast<char16_t>(lo | (hi << 8));
    };
    for (std::size_t i = 0; i < b.size(); i += 2) {
        char32_t cp = unit(i);
        if (cp >= 0xD800 && cp <= 0xDBFF && i + 2 < b.size()) {
            const char16_t lo = unit(i + 2);
            if (lo >= 0xDC00 && lo <= 0xDFFF) {
                cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
                i += 2;
            }
        }
        if (cp >= 0xD800 && cp <= 0xDFFF) throwInputError({fileName}, "invalid UTF-16 (unpaired surrogate)");
        appendUtf8(out, cp);
    }
    return out;
}

double unitScale(std::string_view unit) {
    if (text::iequals(unit, "MM")) return 1.0;
    if (text::iequals(unit, "CM")) return 10.0;
    if (text::iequals(unit, "IN")) return 25.4;
    if (text::iequals(unit, "METER") || text::iequals(unit, "M")) return 1000.0;
    return 0.0;
}

// Gradient 1 (n = n0 + nr2 r^2) and Gradient 3 (n = n0 + nr2 r^2 + nr4 r^4 + nr6 r^6 + nz1 z + nz2 z^2
// + nz3 z^3), OpticStudio's two polynomial graded media in r^2 and z without dispersion data files.
bool isGradient(std::string_view type) {
    return type == "GRADIENT1" || type == "GRADIENT3";
}

constexpr const char* kOtherGradients =
    "; Gradient 5, 6, 9, 12 and GRADIUM take their index from dispersion files (SGRIN.DAT, GLC.DAT, "
    "GRADIENT_9.DAT, PROFILE.GRD) that a .zmx does not carry, and Gradient 2, 4, 7 and 10 are not "
    "polynomials in r^2 and z: convert them to grin_r=/grin_z= in a .lens file";

struct ZmxSurface {
    SourceLocation where, typeWhere;
    std::string type = "STANDARD";
    double curv = 0.0, disz = 0.0, diam = 0.0, clap = 0.0, conic = 0.0;
    bool diszInfinite = false, stop = false;
    std::string glass;
    std::optional<double> inlineNd, inlineVd;
    SourceLocation glassWhere;
    std::map<int, double> parm;
    std::string coat;
};

} // namespace

std::string decodeZmxText(std::string_view b, const std::string& fileName) {
    if (b.size() >= 2 && static_cast<unsigned char>(b[0]) == 0xFF && static_cast<unsigned char>(b[1]) == 0xFE)
        return fromUtf16(b.substr(2), true, fileName);
    if (b.size() >= 2 && static_cast<unsigned char>(b[0]) == 0xFE && static_cast<unsigned char>(b[1]) == 0xFF)
        return fromUtf16(b.substr(2), false, fileName);
    if (b.size() >= 3 && text::startsWith(b, "\xEF\xBB\xBF")) return std::string(b.substr(3));
    // UTF-16 without a BOM: ASCII text has a zero in every other byte.
    if (b.size() >= 4 && b[0] != 0 && b[1] == 0 && b[2] != 0 && b[3] == 0) return fromUtf16(b, true, fileName);
    if (b.size() >= 4 && b[0] == 0 && b[1] != 0 && b[2] == 0 && b[3] != 0) return fromUtf16(b, false, fileName);
    return std::string(b);
}

namespace {

// A ZMX file's directives, as read.
struct ZmxFile {
    std::string name;
    double scale = 1.0;         ///< lens units to mm
    std::optional<double> enpd; ///< the entrance-pupil diameter, lens units
    std::vector<ZmxSurface> surfs;
    std::map<std::string, int> ignored; ///< directives that do not change the prescription, and how often
    int lines = 0;
};

// The directives of a ZMX file's text: the surfaces' blocks, and the name, unit, entrance pupil and
// the directives ignored. Throws ff::Error (Input) at the directive that cannot be read.
ZmxFile readZmx(const std::string& textUtf8, const std::string& fileName) {
    ZmxFile f;
    int lineNo = 0;
    for (std::string_view line : text::split(textUtf8, '\n')) {
        ++lineNo;
        f.lines = lineNo;
        const auto t = text::tokenize(line);
        if (t.empty()) continue;
        const std::string key = text::toUpper(t[0].text);
        const SourceLocation at{fileName, lineNo, t[0].column};
        auto arg = [&](std::size_t i, const char* what) -> double {
            if (i >= t.size())
                throwInputError({fileName, lineNo, t.back().column + static_cast<int>(t.back().text.size()) + 1},
                                std::string("expected ") + what + " after " + key);
            auto v = text::parseNumber(t[i].text);
            if (!v)
                throwInputError({fileName, lineNo, t[i].column},
                                std::string("expected ") + what + " after " + key + ", got " + text::quoted(t[i].text));
            return *v;
        };
        auto needSurface = [&]() -> ZmxSurface& {
            if (f.surfs.empty()) throwInputError(at, key + " outside a SURF block");
            return f.surfs.back();
        };

        if (key == "UNIT") {
            if (t.size() < 2) throwInputError(at, "expected a lens unit after UNIT (MM, CM, IN or METER)");
            f.scale = unitScale(t[1].text);
            if (f.scale == 0.0)
                throwInputError({fileName, lineNo, t[1].column},
                                "unknown lens unit " + text::quoted(t[1].text) + "; valid units: MM, CM, IN, METER");
        } else if (key == "NAME" && f.surfs.empty()) {
            if (t.size() > 1) f.name = std::string(text::trim(line.substr(static_cast<std::size_t>(t[1].column - 1))));
        } else if (key == "ENPD") {
            f.enpd = arg(1, "the entrance-pupil diameter");
        } else if (key == "SURF") {
            const double n = arg(1, "the surface number");
            if (n != static_cast<double>(f.surfs.size()))
                throwInputError({fileName, lineNo, t[1].column}, "expected SURF " + std::to_string(f.surfs.size()) +
                                                                     " (surfaces in order), got SURF " +
                                                                     std::string(t[1].text));
            f.surfs.push_back({});
            f.surfs.back().where = at;
        } else if (key == "TYPE") {
            ZmxSurface& s = needSurface();
            if (t.size() < 2) throwInputError(at, "expected a surface type after TYPE");
            s.type = text::toUpper(t[1].text);
            s.typeWhere = {fileName, lineNo, t[1].column};
            if (s.type == "GRADIEN1") s.type = "GRADIENT1";
            if (s.type == "GRADIEN3") s.type = "GRADIENT3";
            if (s.type == "TOROIDAL")
                throwInputError(s.typeWhere, "TOROIDAL surfaces are not supported (a torus has no exact shape here); "
                                             "give the surface as BICONICX, its X radius as PARM 1");
            if (s.type != "STANDARD" && s.type != "EVENASPH" && s.type != "BICONICX" && !isGradient(s.type))
                throwInputError(s.typeWhere,
                                "unsupported surface type " + text::quoted(t[1].text) +
                                    "; supported: STANDARD, EVENASPH, BICONICX, GRADIENT1, GRADIENT3 "
                                    "(sequential lenses" +
                                    (text::startsWith(s.type, "GRAD") ? std::string(kOtherGradients) : std::string()) +
                                    ")");
        } else if (key == "CURV") {
            needSurface().curv = arg(1, "a curvature");
        } else if (key == "DISZ") {
            ZmxSurface& s = needSurface();
            if (t.size() >= 2 && text::iequals(t[1].text, "INFINITY"))
                s.diszInfinite = true;
            else
                s.disz = arg(1, "a thickness");
        } else if (key == "DIAM") {
            needSurface().diam = arg(1, "a semi-diameter");
        } else if (key == "CLAP") {
            needSurface().clap = arg(2, "a clear-aperture radius");
        } else if (key == "STOP") {
            needSurface().stop = true;
        } else if (key == "CONI") {
            needSurface().conic = arg(1, "a conic constant");
        } else if (key == "PARM") {
            ZmxSurface& s = needSurface();
            auto index = t.size() > 1 ? text::parseInt(t[1].text) : std::nullopt;
            if (!index || *index > 99)
                throwInputError({fileName, lineNo, t.size() > 1 ? t[1].column : t[0].column + 5},
                                "expected a parameter number 0..99 after PARM");
            s.parm[*index] = arg(2, "a parameter value");
        } else if (key == "GLAS") {
            ZmxSurface& s = needSurface();
            if (t.size() < 2) throwInputError(at, "expected a glass name after GLAS");
            s.glass = std::string(t[1].text);
            s.glassWhere = {fileName, lineNo, t[1].column};
            if (text::iequals(s.glass, "MIRROR"))
                throwInputError(s.glassWhere, isGradient(s.type)
                                                  ? "a gradient-index surface cannot be a MIRROR"
                                                  : "MIRROR surfaces (catadioptric systems) are not supported");
            if (t.size() >= 6) {
                s.inlineNd = text::parseNumber(t[4].text);
                s.inlineVd = text::parseNumber(t[5].text);
            }
        } else if (key == "COAT") {
            if (t.size() > 1) needSurface().coat = std::string(t[1].text);
        } else {
            ++f.ignored[key];
        }
    }

    return f;
}

// The medium of a GRADIENT1 or GRADIENT3 surface in mm: PARM 2 = n0, 3 = nr2, and for GRADIENT3 also
// 4, 5 = nr4, nr6 and 6, 7, 8 = nz1, nz2, nz3 (PARM 1, the maximum step, is not used: the integrator
// keeps its own error target). OpticStudio gives these media no dispersion, so neither do we. A
// coefficient of r^(2k) scales as length^(-2k), one of z^k as length^(-k).
Medium gradientMedium(const ZmxSurface& z, double scale, Reporter& reporter) {
    auto parm = [&](int i) {
        const auto it = z.parm.find(i);
        return it == z.parm.end() ? 0.0 : it->second;
    };
    if (!z.parm.count(2) || !(parm(2) > 1.0) || !std::isfinite(parm(2)))
        throwInputError(z.typeWhere, z.type + " needs its base index n0 > 1 as PARM 2");
    Medium m = Medium::fromNdVd(parm(2), 0.0);
    GradientIndex g;
    g.origin = z.typeWhere;
    const int radialTerms = z.type == "GRADIENT3" ? 3 : 1;
    for (int k = 1; k <= radialTerms; ++k) g.radial.push_back({parm(2 + k) * std::pow(scale, -2 * k), 0.0});
    if (z.type == "GRADIENT3")
        for (int k = 1; k <= 3; ++k) g.axial.push_back({parm(5 + k) * std::pow(scale, -k), 0.0});
    while (!g.radial.empty() && g.radial.back().atD == 0.0) g.radial.pop_back();
    while (!g.axial.empty() && g.axial.back().atD == 0.0) g.axial.pop_back();
    if (!g.radial.empty() || !g.axial.empty()) m.gradient = std::move(g);
    std::string note = z.type + ": n0 " + text::roundTrip(parm(2)) + " and its coefficients at every wavelength";
    if (!z.glass.empty()) note += "; the glass " + text::quoted(z.glass) + " is not used";
    reporter.note(z.typeWhere, note);
    return m;
}

// One lens surface of the file in mm, its glass and coating resolved (notes for the inline glass and
// the unknown coating).
Surface toSurface(const ZmxSurface& z, double scale, Reporter& reporter) {
    Surface s;
    s.origin = z.where;
    if (z.diszInfinite)
        throwInputError(z.where, "DISZ INFINITY on a lens surface (only the object may be at infinity)");
    s.radius = z.curv == 0.0 ? 0.0 : 1.0 / (z.curv / scale);
    s.thickness = z.disz * scale;
    s.conic = z.conic;
    s.semiAperture = (z.clap > 0.0 ? z.clap : z.diam) * scale;
    s.stop = z.stop;
    if (z.type == "EVENASPH") {
        if (auto a2 = z.parm.find(1); a2 != z.parm.end() && a2->second != 0.0)
            throwInputError(z.where, "EVENASPH with an r^2 term (PARM 1) is not supported; only A4 and higher");
        for (const auto& [idx, val] : z.parm) {
            if (idx < 2 || idx > 11) continue;
            s.asphere.resize(std::max<std::size_t>(s.asphere.size(), static_cast<std::size_t>(idx - 1)), 0.0);
            // A coefficient of r^(2k) scales as length^(1-2k) when lengths are converted.
            s.asphere[static_cast<std::size_t>(idx - 2)] = val * std::pow(scale, 1 - 2 * idx);
        }
        while (!s.asphere.empty() && s.asphere.back() == 0.0) s.asphere.pop_back();
    }
    if (z.type == "BICONICX") {
        // OpticStudio's biconic: CURV and CONI are the y-z section's, PARM 1 the X radius (0: flat in
        // x) and PARM 2 the X conic; no other parameter.
        for (const auto& [idx, val] : z.parm)
            if ((idx < 1 || idx > 2) && val != 0.0)
                throwInputError(z.typeWhere,
                                "BICONICX with PARM " + std::to_string(idx) +
                                    " is not supported (only PARM 1, the X radius, and PARM 2, the X conic)");
        const auto x = z.parm.find(1), k = z.parm.find(2);
        s.shape = SurfaceShape::Biconic;
        s.radiusX = x == z.parm.end() ? 0.0 : x->second * scale;
        s.conicX = k == z.parm.end() ? 0.0 : k->second;
    }
    if (isGradient(z.type)) {
        s.medium = gradientMedium(z, scale, reporter);
    } else if (z.glass.empty() || text::iequals(z.glass, "AIR")) {
        s.medium = Medium::air();
    } else if (GlassCatalog::builtin().find(z.glass)) {
        s.medium = GlassCatalog::builtin().medium(z.glass, z.glassWhere);
    } else if (z.inlineNd && *z.inlineNd >= 1.0 && *z.inlineNd <= 4.0) {
        s.medium = Medium::fromNdVd(*z.inlineNd, z.inlineVd.value_or(0.0) > 0.0 ? *z.inlineVd : 0.0);
        reporter.note(z.glassWhere,
                      "glass " + text::quoted(z.glass) + " is not in the catalogue; using its inline nd " +
                          text::roundTrip(s.medium.nd) + ", Vd " + text::roundTrip(s.medium.vd) + " (Cauchy)");
    } else {
        GlassCatalog::builtin().get(z.glass, z.glassWhere); // throws with the closest names
    }
    if (!z.coat.empty()) {
        if (text::iequals(z.coat, "AR")) {
            s.coating = CoatingSpec::mgf2();
            s.coatingLayers = 1;
        } else {
            reporter.note(z.where, "coating " + text::quoted(z.coat) + " is not known; the surface is left bare");
        }
    }
    return s;
}

// Aperture: the stop's DIAM, else the system entrance-pupil diameter (ENPD): the stop opening whose
// paraxial image in object space has that diameter (EPD = 2 r / |yA| at the stop).
void stopFromEnpd(Lens& lens, const ZmxFile& f, Reporter& reporter) {
    for (std::size_t i = 0; i < lens.surfaces.size(); ++i) {
        Surface& s = lens.surfaces[i];
        if (!s.stop || s.semiAperture > 0.0 || !f.enpd || *f.enpd <= 0.0) continue;
        const double yA = heightAt(lens, lines::d, {1.0, 0.0}, 0, i);
        s.semiAperture = 0.5 * *f.enpd * f.scale * std::abs(yA);
        reporter.note(s.origin, "stop semi-aperture " + text::fixed(s.semiAperture, 4) + " mm from ENPD " +
                                    text::roundTrip(*f.enpd * f.scale) + " mm");
    }
}

} // namespace

Lens importZmx(std::string_view bytes, const std::string& fileName, Reporter* reporterIn) {
    Reporter& reporter = orNull(reporterIn);
    const std::string textUtf8 = decodeZmxText(bytes, fileName);
    checkIsText(textUtf8, fileName);
    const ZmxFile f = readZmx(textUtf8, fileName);
    const std::vector<ZmxSurface>& surfs = f.surfs;
    const double scale = f.scale;

    Lens lens;
    lens.file = fileName;
    lens.format = "zmx";
    lens.name = f.name;
    if (surfs.size() < 3)
        throwInputError({fileName, f.lines, 0},
                        "expected at least an object surface (SURF 0), one lens surface and an image surface, found " +
                            std::to_string(surfs.size()) + " SURF block(s)");
    if (!surfs.front().diszInfinite)
        reporter.note(surfs.front().where, "the object distance " + text::roundTrip(surfs.front().disz * scale) +
                                               " mm is ignored: FourierFlare images sources at infinity");

    for (std::size_t i = 1; i + 1 < surfs.size(); ++i) lens.surfaces.push_back(toSurface(surfs[i], scale, reporter));
    const ZmxSurface& image = surfs.back();
    if (image.curv != 0.0)
        reporter.note(image.where, "the image surface is curved; FourierFlare uses a flat sensor at its vertex");

    if (!f.ignored.empty()) {
        std::vector<std::string> names;
        int total = 0;
        for (const auto& [k, n] : f.ignored) {
            names.push_back(k);
            total += n;
        }
        reporter.note({fileName}, "ignored " + std::to_string(total) +
                                      " directive(s) that do not affect the prescription: " + text::join(names));
    }
    stopFromEnpd(lens, f, reporter);
    validateLens(lens, {fileName, surfs.front().where.line, 0}, reporter);
    return lens;
}

} // namespace ff::optics
