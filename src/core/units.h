#pragma once
// Units used across FourierFlare: lengths in millimetres, wavelengths in nanometres (lambdaNm),
// angles in radians inside the code and degrees at the user interface.

#include <numbers>

namespace ff {

/// Fraunhofer lines (nm), from reference/optics.md.
namespace lines {
inline constexpr double g = 435.8343;
inline constexpr double Fprime = 479.9914;
inline constexpr double F = 486.1327;
inline constexpr double e = 546.0740;
inline constexpr double d = 587.5618;
inline constexpr double D = 589.2938;
inline constexpr double Cprime = 643.8469;
inline constexpr double C = 656.2725;
} // namespace lines

inline constexpr double nmToUm(double lambdaNm) {
    return lambdaNm * 1e-3;
}
inline constexpr double degToRad(double deg) {
    return deg * std::numbers::pi / 180.0;
}
inline constexpr double radToDeg(double rad) {
    return rad * 180.0 / std::numbers::pi;
}

} // namespace ff
