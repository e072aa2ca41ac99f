#include "optics/surface.h"

#include <glm/geometric.hpp>

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

// From the implicit conic for spheres and conics, from the sag slope n ∝ (-z'(r) x / r, -z'(r) y / r,
// 1) for aspheres.
std::optional<glm::dvec3> Surface::normal(const glm::dvec3& local) const {
    const Surface& s = *this;
    if (!s.isAspheric()) {
        // Sphere or conic: minus the gradient of c (x^2 + y^2 + (1 + k) z^2) - 2 z, which points to +z.
        const double c = s.curvature();
        return glm::normalize(glm::dvec3(-c * local.x, -c * local.y, 1.0 - c * (1.0 + s.conic) * local.z));
    }
    const double r = std::sqrt(local.x * local.x + local.y * local.y);
    auto slope = s.sagSlope(r);
    if (!slope || !std::isfinite(*slope)) return std::nullopt;
    glm::dvec3 n(0.0, 0.0, 1.0);
    if (r > 0.0) n = glm::dvec3(-*slope * local.x / r, -*slope * local.y / r, 1.0);
    return glm::normalize(n);
}

} // namespace ff::optics
