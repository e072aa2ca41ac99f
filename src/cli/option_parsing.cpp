#include "cli/option_parsing.h"

#include "core/error.h"
#include "core/text.h"

#include <cmath>
#include <optional>

namespace ff::cli {

std::pair<double, double> parsePair(const std::string& s, char sep, const char* what) {
    const auto parts = text::split(s, sep);
    const auto a = parts.size() == 2 ? text::parseNumber(parts[0]) : std::nullopt;
    const auto b = parts.size() == 2 ? text::parseNumber(parts[1]) : std::nullopt;
    if (!a || !b || !std::isfinite(*a) || !std::isfinite(*b))
        throw Error(ErrorKind::Usage, std::string("expected ") + what + ", got " + text::quoted(s));
    return {*a, *b};
}

std::pair<int, int> parseFrameSize(const std::string& s, const char* option, int lo, int hi) {
    const auto [w, h] = parsePair(s, 'x', (std::string(option) + " WIDTHxHEIGHT in pixels (e.g. 1280x720)").c_str());
    if (w < lo || h < lo || w > hi || h > hi || w != std::floor(w) || h != std::floor(h))
        throw Error(ErrorKind::Usage, std::string(option) + " must be whole pixels between " + std::to_string(lo) +
                                          " and " + std::to_string(hi) + ", got " + text::quoted(s));
    return {static_cast<int>(w), static_cast<int>(h)};
}

std::pair<double, double> parseSensorSize(const std::string& s, const char* option) {
    const auto [w, h] = parsePair(s, 'x', (std::string(option) + " WIDTHxHEIGHT in mm (e.g. 36x24)").c_str());
    if (!(w > 0.0) || !(h > 0.0) || w > 1000.0 || h > 1000.0)
        throw Error(ErrorKind::Usage,
                    std::string(option) + " must be positive and at most 1000 mm, got " + text::quoted(s));
    return {w, h};
}

std::pair<double, double> parseAngle(const std::string& s, const char* option) {
    const auto parts = text::split(s, ',');
    const auto deg = parts.size() <= 2 ? text::parseNumber(parts[0]) : std::nullopt;
    const auto az = parts.size() == 2 ? text::parseNumber(parts[1]) : std::optional<double>(0.0);
    if (!deg || !az || *deg < 0.0 || *deg >= 89.0)
        throw Error(ErrorKind::Usage,
                    std::string("expected ") + option + " DEG[,AZ] with 0 <= DEG < 89, got " + text::quoted(s));
    return {*deg, *az};
}

} // namespace ff::cli
