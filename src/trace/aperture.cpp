#include "trace/aperture.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace ff::trace {

Iris::Iris(int n, double rotation, double r) : blades(n), rotationRad(rotation), radius(r), circumradius(r) {
    if (blades >= 3)
        circumradius = r * std::sqrt(2.0 * std::numbers::pi / (blades * std::sin(2.0 * std::numbers::pi / blades)));
}

bool Iris::contains(double x, double y) const {
    const double rho2 = x * x + y * y;
    if (blades < 3) return rho2 <= radius * radius;
    if (rho2 > circumradius * circumradius) return false;
    // Distance to the edge along the direction phi: inradius / cos(angle from the edge's normal).
    const double sector = 2.0 * std::numbers::pi / blades;
    const double inradius = circumradius * std::cos(0.5 * sector);
    double a = std::fmod(std::atan2(y, x) - rotationRad, sector);
    if (a < 0.0) a += sector;
    const double rhoMax = inradius / std::cos(a - 0.5 * sector);
    return rho2 <= rhoMax * rhoMax;
}

double Iris::margin(double x, double y) const {
    if (blades < 3) return radius - std::hypot(x, y);
    // The polygon is the intersection of the blades' half-planes p . n_k <= inradius, n_k the edge
    // normals at rotation + (k + 1/2) sector.
    const double sector = 2.0 * std::numbers::pi / blades;
    const double inradius = circumradius * std::cos(0.5 * sector);
    double reach = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < blades; ++k) {
        const double phi = rotationRad + (k + 0.5) * sector;
        reach = std::max(reach, x * std::cos(phi) + y * std::sin(phi));
    }
    return inradius - reach;
}

bool Iris::mirrorSymmetricAbout(double lineRad) const {
    if (blades < 3) return true;
    return std::abs(std::remainder(lineRad - rotationRad, std::numbers::pi / blades)) < 1e-9;
}

} // namespace ff::trace
