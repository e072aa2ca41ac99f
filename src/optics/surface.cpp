#include "optics/surface.h"

#include <cmath>

namespace ff::optics {

const char* toString(SurfaceShape s) {
    switch (s) {
    case SurfaceShape::Spherical:
        return "sph";
    case SurfaceShape::CylinderX:
        return "cyl_x";
    case SurfaceShape::CylinderY:
        return "cyl_y";
    case SurfaceShape::Toric:
        return "toric";
    }
    return "sph";
}

std::optional<double> Surface::sag(double r) const {
    const double c = curvature();
    const double r2 = r * r;
    const double disc = 1.0 - (1.0 + conic) * c * c * r2;
    if (disc < 0.0) return std::nullopt;
    double z = c * r2 / (1.0 + std::sqrt(disc));
    double r2k = r2 * r2; // r^4, r^6, ...
    for (double a : asphere) {
        z += a * r2k;
        r2k *= r2;
    }
    return z;
}

std::optional<double> Surface::sagSlope(double r) const {
    const double c = curvature();
    const double disc = 1.0 - (1.0 + conic) * c * c * r * r;
    if (disc < 0.0) return std::nullopt;
    // d/dr [c r^2 / (1 + sqrt(1 - (1+k) c^2 r^2))] = c r / sqrt(1 - (1+k) c^2 r^2)
    double dz = (disc > 0.0) ? c * r / std::sqrt(disc) : (c == 0.0 ? 0.0 : HUGE_VAL);
    double rk = r * r * r; // r^3, r^5, ...
    int power = 4;
    for (double a : asphere) {
        dz += power * a * rk;
        rk *= r * r;
        power += 2;
    }
    return dz;
}

} // namespace ff::optics
