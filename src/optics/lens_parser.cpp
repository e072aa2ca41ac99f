#include "optics/lens_parser.h"

#include "core/text.h"
#include "optics/glass_catalog.h"
#include "optics/lens_validation.h"

#include <cctype>
#include <cmath>
#include <limits>

namespace ff::optics {

namespace {

using text::Token;

constexpr const char* kHeaderKeys[] = {"name",           "focal_length", "f_number", "sensor", "aperture_blades",
                                       "blade_rotation", "coating",      "source",   "patent", "zoom_positions"};
constexpr const char* kColumns =
    "radius thickness ior abbe semi_ap [coating]  (or: radius thickness GLASS semi_ap [coating])";
constexpr std::size_t kMaxSurfaces = 1000;

class LensTextParser {
  public:
    LensTextParser(std::string_view text, std::string file, Reporter& reporter)
        : text_(text), file_(std::move(file)), reporter_(reporter) {
        lens_.file = file_;
    }

    Lens parse() {
        int lineNo = 0;
        for (std::string_view line : text::split(text_, '\n')) {
            ++lineNo;
            line_ = lineNo;
            if (lineNo == 1 && text::startsWith(line, "\xEF\xBB\xBF")) line.remove_prefix(3); // UTF-8 BOM
            const auto tokens = text::tokenize(line);
            if (tokens.empty()) continue;
            if (!inSurfaces_) {
                parseHeaderLine(line, tokens);
            } else {
                if (isKeyLine(tokens[0].text))
                    fail(tokens[0].column, "header key " + text::quoted(tokens[0].text) +
                                               " after 'surfaces:'; header keys must come before the surface rows");
                parseRow(tokens);
            }
        }
        line_ = lineNo;
        if (!inSurfaces_)
            failAt({file_, lineNo, 0},
                   "no 'surfaces:' section: expected a line 'surfaces:' followed by one row per surface");
        if (lens_.surfaces.empty()) failAt(surfacesLine_, "the 'surfaces:' section has no surface rows");
        finishZoom();
        validateLens(lens_, surfacesLine_, reporter_);
        return std::move(lens_);
    }

  private:
    [[noreturn]] void fail(int column, const std::string& msg) const { failAt({file_, line_, column}, msg); }
    [[noreturn]] void failAt(const SourceLocation& at, const std::string& msg) const { throwInputError(at, msg); }
    SourceLocation at(int column) const { return {file_, line_, column}; }

    static bool isKeyLine(std::string_view first) {
        const auto colon = first.find(':');
        if (colon == std::string_view::npos || colon == 0) return false;
        for (char c : first.substr(0, colon))
            if (!(std::isalpha(static_cast<unsigned char>(c)) || c == '_')) return false;
        return true;
    }

    double number(const Token& t, const char* what) const {
        auto v = text::parseNumber(t.text);
        if (!v) fail(t.column, std::string("expected a number for '") + what + "', got " + text::quoted(t.text));
        return *v;
    }

    // ---------------------------------------------------------------- header
    void parseHeaderLine(std::string_view line, const std::vector<Token>& tokens) {
        if (tokens[0].text == "surfaces:") {
            if (tokens.size() > 1)
                fail(tokens[1].column, "unexpected " + text::quoted(tokens[1].text) + " after 'surfaces:'");
            inSurfaces_ = true;
            surfacesLine_ = at(tokens[0].column);
            return;
        }
        const std::string_view first = tokens[0].text;
        const auto colon = first.find(':');
        if (colon == std::string_view::npos || !isKeyLine(first)) {
            if (text::parseNumber(first) || first == "stop")
                fail(tokens[0].column, "surface row before 'surfaces:'; add a line 'surfaces:' above the rows");
            fail(tokens[0].column, "expected 'key: value' or 'surfaces:', got " + text::quoted(first));
        }
        const std::string key(first.substr(0, colon));
        bool known = false;
        for (const char* k : kHeaderKeys) known = known || key == k;
        if (!known) {
            std::vector<std::string> keys(std::begin(kHeaderKeys), std::end(kHeaderKeys));
            keys.push_back("surfaces");
            fail(tokens[0].column,
                 "unknown header key " + text::quoted(key) + "; " + text::suggestion(key, keys, "keys"));
        }
        for (const auto& seen : seenKeys_)
            if (seen == key) fail(tokens[0].column, "duplicate header key " + text::quoted(key));
        seenKeys_.push_back(key);

        // The value: everything after the colon up to a comment.
        const std::size_t valueStart = static_cast<std::size_t>(tokens[0].column - 1) + colon + 1;
        std::vector<Token> value;
        for (const Token& t : text::tokenize(line.substr(valueStart)))
            value.push_back({t.text, t.column + static_cast<int>(valueStart)});
        const int keyCol = tokens[0].column;
        const int endCol = keyCol + static_cast<int>(first.size());
        auto needValues = [&](std::size_t n, const char* form) {
            if (value.size() < n) fail(endCol + 1, "expected " + std::string(form) + " after '" + key + ":'");
            if (value.size() > n)
                fail(value[n].column,
                     "unexpected " + text::quoted(value[n].text) + " after the value of '" + key + ":'");
        };
        auto rest = [&]() -> std::string {
            if (value.empty()) fail(endCol + 1, "expected a value after '" + key + ":'");
            return std::string(text::trim(line.substr(
                static_cast<std::size_t>(value.front().column - 1),
                static_cast<std::size_t>(value.back().column - value.front().column) + value.back().text.size())));
        };

        if (key == "name")
            lens_.name = rest();
        else if (key == "source")
            lens_.source = rest();
        else if (key == "patent")
            lens_.patent = rest();
        else if (key == "focal_length") {
            needValues(1, "a focal length in mm");
            const std::string lower = text::toLower(value[0].text);
            const double f = lower == "inf" || lower == "infinity" ? std::numeric_limits<double>::infinity()
                                                                   : number(value[0], "focal_length");
            if (f == 0.0) fail(value[0].column, "'focal_length' must not be 0 (write 'inf' for an afocal lens)");
            lens_.nominalFocalLength = f;
        } else if (key == "f_number") {
            needValues(1, "an f-number");
            const double n = number(value[0], "f_number");
            if (n < 0.3 || n > 1000.0)
                fail(value[0].column, "'f_number' must be between 0.3 and 1000, got " + text::quoted(value[0].text));
            lens_.fNumber = n;
        } else if (key == "sensor") {
            parseSensor(value, endCol);
        } else if (key == "aperture_blades") {
            needValues(1, "a blade count");
            auto n = text::parseInt(value[0].text);
            if (!n || *n == 1 || *n == 2 || *n > 64)
                fail(value[0].column,
                     "expected a blade count of 0 (circular) or 3..64, got " + text::quoted(value[0].text));
            lens_.apertureBlades = *n;
        } else if (key == "blade_rotation") {
            needValues(1, "an angle in degrees");
            lens_.bladeRotationDeg = number(value[0], "blade_rotation");
        } else if (key == "coating") {
            const std::string spec = rest();
            lens_.defaultCoating = parseCoatingSpec(spec, at(value.front().column));
        } else if (key == "zoom_positions") {
            if (value.size() < 2)
                fail(value.empty() ? endCol + 1 : value[0].column,
                     "expected at least two zoom position labels after 'zoom_positions:'");
            for (const Token& t : value) {
                for (const auto& l : lens_.zoomLabels)
                    if (l == t.text) fail(t.column, "duplicate zoom position label " + text::quoted(t.text));
                lens_.zoomLabels.emplace_back(t.text);
            }
        }
    }

    void parseSensor(const std::vector<Token>& value, int endCol) {
        // "36x24", "36 x 24" or "36 24" (mm).
        std::string joined;
        for (const Token& t : value) joined += std::string(t.text) + " ";
        std::string_view s = text::trim(joined);
        const auto x = s.find_first_of("xX");
        std::string_view w = x == std::string_view::npos ? s.substr(0, s.find(' ')) : text::trim(s.substr(0, x));
        std::string_view h =
            x == std::string_view::npos
                ? (s.find(' ') == std::string_view::npos ? std::string_view{} : text::trim(s.substr(s.find(' '))))
                : text::trim(s.substr(x + 1));
        auto wv = text::parseNumber(w), hv = text::parseNumber(h);
        const int col = value.empty() ? endCol + 1 : value[0].column;
        if (!wv || !hv || *wv <= 0.0 || *hv <= 0.0 || *wv > 1000.0 || *hv > 1000.0)
            fail(col, "expected the sensor size as WIDTHxHEIGHT in mm (e.g. 36x24), got " + text::quoted(s));
        lens_.sensorMm = std::make_pair(*wv, *hv);
    }

    // ---------------------------------------------------------------- surface rows
    void parseRow(const std::vector<Token>& t) {
        if (lens_.surfaces.size() >= kMaxSurfaces)
            fail(t[0].column,
                 "more than " + std::to_string(kMaxSurfaces) + " surfaces; this is not a lens prescription");
        Surface s;
        s.origin = at(t[0].column);
        const std::size_t index = lens_.surfaces.size();

        // radius
        if (t[0].text == "stop") {
            s.stop = s.flatStopRow = true;
        } else if (text::iequals(t[0].text, "inf") || text::iequals(t[0].text, "infinity") ||
                   text::iequals(t[0].text, "flat")) {
            s.radius = 0.0;
        } else {
            auto r = text::parseNumber(t[0].text);
            if (!r)
                fail(t[0].column, "expected a number, 'inf' or 'stop' for 'radius', got " + text::quoted(t[0].text));
            s.radius = *r;
        }
        if (t.size() < 2) short_(t, 1);

        // thickness: number, comma list (zoom) or 'auto' (last row)
        std::vector<double> gaps;
        if (t[1].text == "auto") {
            autoRow_ = at(t[1].column);
            autoIndex_ = index;
        } else if (t[1].text.find(',') != std::string_view::npos) {
            int col = t[1].column;
            for (std::string_view part : text::split(t[1].text, ',')) {
                auto v = text::parseNumber(part);
                if (!v) fail(col, "expected a number in the zoom thickness list, got " + text::quoted(part));
                gaps.push_back(*v);
                col += static_cast<int>(part.size()) + 1;
            }
            if (lens_.zoomLabels.empty())
                fail(t[1].column, "a thickness list (zoom) needs 'zoom_positions:' in the header");
            if (gaps.size() != lens_.zoomLabels.size())
                fail(t[1].column, "expected " + std::to_string(lens_.zoomLabels.size()) +
                                      " thicknesses (one per zoom position), got " + std::to_string(gaps.size()));
            s.thickness = gaps[0];
        } else {
            s.thickness = number(t[1], "thickness");
        }
        if (std::abs(s.thickness) > 1e5) fail(t[1].column, "thickness " + text::quoted(t[1].text) + " is beyond 100 m");
        if (t.size() < 3) short_(t, 2);

        // medium: "ior abbe" or a glass name
        std::size_t next;
        if (auto ior = text::parseNumber(t[2].text)) {
            if (*ior < 1.0 || *ior > 4.0)
                fail(t[2].column,
                     "expected a refractive index between 1 and 4 for 'ior', got " + text::quoted(t[2].text));
            if (t.size() < 4) short_(t, 3);
            const double abbe = number(t[3], "abbe");
            if (abbe < 0.0 || abbe > 200.0)
                fail(t[3].column,
                     "expected an Abbe number between 0 and 200 (0 = no dispersion), got " + text::quoted(t[3].text));
            s.medium = (*ior == 1.0 && abbe == 0.0) ? Medium::air() : Medium::fromNdVd(*ior, abbe);
            next = 4;
        } else {
            const std::string_view g = t[2].text;
            if (text::iequals(g, "air"))
                s.medium = Medium::air();
            else if (!std::isalpha(static_cast<unsigned char>(g[0])))
                fail(t[2].column, "expected a number for 'ior' or a glass name, got " + text::quoted(g));
            else
                s.medium = GlassCatalog::builtin().medium(g, at(t[2].column));
            next = 3;
        }
        if (t.size() <= next) short_(t, next);

        // semi-aperture
        s.semiAperture = number(t[next], "semi_ap");
        if (s.semiAperture < 0.0)
            fail(t[next].column, "negative semi-aperture " + text::quoted(t[next].text) +
                                     "; expected the clear semi-diameter in mm (>= 0)");
        if (s.semiAperture > 1e4) {
            // Libraries write 1e6 and the like for "no limit" (the Hologon's rear surfaces).
            reporter_.note(at(t[next].column), "semi-aperture " + text::quoted(t[next].text) +
                                                   " is beyond 10 m: read as unlimited (unclipped)");
            s.semiAperture = 0.0;
        }
        ++next;

        // optional coating column (a whole number of layers)
        if (next < t.size() && !t[next].text.empty() && std::isdigit(static_cast<unsigned char>(t[next].text[0]))) {
            auto n = text::parseInt(t[next].text);
            if (!n || *n > 20)
                fail(t[next].column, "expected a whole number of coating layers (0..20) for 'coating', got " +
                                         text::quoted(t[next].text));
            s.coatingLayers = *n;
            ++next;
        } else {
            // No coating column: a glass-air interface gets the lens-wide coating, others none.
            const bool beforeAir = lens_.surfaces.empty() || lens_.surfaces.back().medium.isAir();
            s.coatingLayers = (beforeAir != s.medium.isAir()) ? 1 : 0;
        }

        // extensions
        for (; next < t.size(); ++next) parseExtra(s, t, next);
        lens_.surfaces.push_back(std::move(s));
        lens_.zoomGaps.push_back(std::move(gaps));
    }

    void parseExtra(Surface& s, const std::vector<Token>& t, std::size_t& i) {
        const Token& tok = t[i];
        const std::string_view v = tok.text;
        if (v == "stop") {
            if (s.stop) fail(tok.column, "'stop' given twice in one row");
            s.stop = true;
            return;
        }
        if (v == "sph" || v == "cyl_x" || v == "cyl_y" || v == "toric") {
            s.shape = v == "sph"     ? SurfaceShape::Spherical
                      : v == "cyl_x" ? SurfaceShape::CylinderX
                      : v == "cyl_y" ? SurfaceShape::CylinderY
                                     : SurfaceShape::Toric;
            if (i + 1 < t.size() && text::parseNumber(t[i + 1].text)) s.radiusY = *text::parseNumber(t[++i].text);
            return;
        }
        const auto eq = v.find('=');
        if (eq != std::string_view::npos) {
            const std::string_view key = v.substr(0, eq), val = v.substr(eq + 1);
            const int valCol = tok.column + static_cast<int>(eq) + 1;
            if (val.empty()) fail(valCol, "expected a value after '" + std::string(key) + "='");
            if (key == "conic") {
                auto k = text::parseNumber(val);
                if (!k) fail(valCol, "expected a number for 'conic', got " + text::quoted(val));
                s.conic = *k;
                return;
            }
            if (key == "asph") {
                int col = valCol;
                for (std::string_view part : text::split(val, ',')) {
                    auto a = text::parseNumber(part);
                    if (!a) fail(col, "expected a number in 'asph=A4,A6,...', got " + text::quoted(part));
                    s.asphere.push_back(*a);
                    col += static_cast<int>(part.size()) + 1;
                }
                if (s.asphere.size() > 10) fail(valCol, "at most 10 asphere terms (A4..A22) are supported");
                while (!s.asphere.empty() && s.asphere.back() == 0.0) s.asphere.pop_back();
                return;
            }
            if (key == "coating") {
                s.coating = parseCoatingSpec(val, at(valCol));
                return;
            }
            if (key == "biconic") {
                // biconic=RX[,KX]: the x-z section's radius (0 or inf: flat) and conic; the row's radius
                // and conic= are the y-z section's.
                const auto parts = text::split(val, ',');
                if (parts.size() > 2) fail(valCol, "expected 'biconic=RX' or 'biconic=RX,KX'");
                int col = valCol;
                std::array<double, 2> rk{0.0, 0.0};
                for (std::size_t k = 0; k < parts.size(); ++k) {
                    const auto x = parts[k] == "inf" && k == 0 ? std::optional(0.0) : text::parseNumber(parts[k]);
                    if (!x || !std::isfinite(*x))
                        fail(col, std::string("expected a number for the x-z section's ") +
                                      (k == 0 ? "radius" : "conic") + " in 'biconic=RX,KX', got " +
                                      text::quoted(parts[k]));
                    rk[k] = *x;
                    col += static_cast<int>(parts[k].size()) + 1;
                }
                if (s.shape != SurfaceShape::Spherical)
                    fail(tok.column,
                         std::string("'biconic=' on a ") + toString(s.shape) + " surface (one shape a row)");
                s.shape = SurfaceShape::Biconic;
                s.radiusX = rk[0];
                s.conicX = rk[1];
                return;
            }
            if (key == "grin_r" || key == "grin_z") {
                parseGradient(s, key, val, tok.column, valCol);
                return;
            }
            fail(tok.column, "unknown surface option " + text::quoted(key) +
                                 "; valid options: conic=K, asph=A4,A6,..., biconic=RX[,KX], coating=SPEC, "
                                 "grin_r=A1:D1,..., grin_z=B1:D1,...");
        }
        fail(tok.column, "unexpected " + text::quoted(v) +
                             " after the surface columns; expected 'stop', a shape "
                             "(sph, cyl_x, cyl_y, toric), conic=K, asph=A4,A6,..., biconic=RX[,KX], coating=SPEC, "
                             "grin_r=... or grin_z=...");
    }

    // grin_r=A1:D1,A2:D2,... (coefficients of r^2, r^4, ...) or grin_z=B1:D1,... (of z, z^2, ...): each
    // coefficient at the d line and its dispersion D (GradientTerm), both required.
    void parseGradient(Surface& s, std::string_view key, std::string_view val, int keyCol, int valCol) const {
        if (!s.medium.gradient) {
            s.medium.gradient.emplace();
            s.medium.gradient->origin = at(keyCol);
        }
        auto& terms = key == "grin_r" ? s.medium.gradient->radial : s.medium.gradient->axial;
        if (!terms.empty()) fail(keyCol, "'" + std::string(key) + "' given twice in one row");
        int col = valCol;
        for (std::string_view part : text::split(val, ',')) {
            const auto colon = part.find(':');
            if (colon == std::string_view::npos)
                fail(col, "the gradient coefficient " + text::quoted(part) +
                              " has no dispersion: write VALUE:D (c(lambda) = VALUE + D (1/L^2 - 1/Ld^2), L in um; "
                              "D = 0 for none)");
            const auto value = text::parseNumber(part.substr(0, colon));
            const auto dispersion = text::parseNumber(part.substr(colon + 1));
            if (!value) fail(col, "expected a number before ':' in " + text::quoted(part));
            if (!dispersion)
                fail(col + static_cast<int>(colon) + 1, "expected a number after ':' in " + text::quoted(part));
            terms.push_back({*value, *dispersion});
            col += static_cast<int>(part.size()) + 1;
        }
        if (terms.size() > 10) fail(valCol, "at most 10 gradient terms are supported");
    }

    [[noreturn]] void short_(const std::vector<Token>& t, std::size_t have) const {
        const Token& last = t.back();
        fail(last.column + static_cast<int>(last.text.size()) + 1,
             "short row: found " + std::to_string(have) + " column(s), expected " + kColumns);
    }

    void finishZoom() {
        if (autoIndex_ && *autoIndex_ + 1 != lens_.surfaces.size())
            failAt(autoRow_, "'auto' thickness is only allowed on the last row (the distance to the sensor)");
        lens_.imageDistanceAuto = autoIndex_.has_value();
        if (!lens_.zoomLabels.empty()) {
            bool any = false;
            for (const auto& g : lens_.zoomGaps) any = any || !g.empty();
            if (!any) failAt(surfacesLine_, "'zoom_positions:' is given but no row has a thickness list (a,b,...)");
        } else {
            lens_.zoomGaps.clear();
        }
    }

    std::string_view text_;
    std::string file_;
    Reporter& reporter_;
    Lens lens_;
    int line_ = 0;
    bool inSurfaces_ = false;
    SourceLocation surfacesLine_;
    SourceLocation autoRow_;
    std::optional<std::size_t> autoIndex_;
    std::vector<std::string> seenKeys_;
};

} // namespace

void checkIsText(std::string_view text, const std::string& fileName) {
    int line = 1, col = 1;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c == '\n') {
            ++line;
            col = 1;
            continue;
        }
        if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f)
            throwInputError({fileName, line, col}, c == 0 ? "not a text file (NUL byte)"
                                                          : "unexpected control character " +
                                                                text::quoted(text.substr(i, 1)) +
                                                                "; is this a text file?");
        if (c >= 0x80) {
            // Validate one UTF-8 sequence.
            const int len = (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
            bool ok = len > 0 && i + static_cast<std::size_t>(len) <= text.size();
            for (int k = 1; ok && k < len; ++k) ok = (static_cast<unsigned char>(text[i + k]) >> 6) == 0x2;
            if (!ok)
                throwInputError({fileName, line, col},
                                "invalid UTF-8 byte; is this a text file (or UTF-16, which only .zmx may use)?");
            i += static_cast<std::size_t>(len - 1);
        }
        ++col;
    }
}

Lens parseLensText(std::string_view text, const std::string& fileName, Reporter* reporter) {
    checkIsText(text, fileName);
    return LensTextParser(text, fileName, orNull(reporter)).parse();
}

} // namespace ff::optics
