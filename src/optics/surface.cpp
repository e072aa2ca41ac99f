#include "optics/surface.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <numbers>

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
    case SurfaceShape::Biconic:
        return "biconic";
    }
    return "sph";
}

double Surface::curvatureX() const {
    switch (shape) {
    case SurfaceShape::CylinderX:
        return 0.0;
    case SurfaceShape::Biconic:
        return radiusX == 0.0 ? 0.0 : 1.0 / radiusX;
    default:
        return curvature();
    }
}

double Surface::curvatureY() const {
    return shape == SurfaceShape::CylinderY ? 0.0 : curvature();
}

double Surface::conicOfX() const {
    switch (shape) {
    case SurfaceShape::CylinderX:
        return 0.0;
    case SurfaceShape::Biconic:
        return conicX;
    default:
        return conic;
    }
}

double Surface::conicOfY() const {
    return shape == SurfaceShape::CylinderY ? 0.0 : conic;
}

std::optional<double> Surface::sagAt(double x, double y) const {
    if (rotationallySymmetric()) return sag(std::sqrt(x * x + y * y));
    const double cx = curvatureX(), cy = curvatureY();
    const double disc = 1.0 - (1.0 + conicOfX()) * cx * cx * x * x - (1.0 + conicOfY()) * cy * cy * y * y;
    if (disc < 0.0) return std::nullopt;
    return (cx * x * x + cy * y * y) / (1.0 + std::sqrt(disc));
}

std::optional<glm::dvec2> Surface::sagGradient(double x, double y) const {
    if (rotationallySymmetric()) {
        const double r = std::sqrt(x * x + y * y);
        const auto slope = sagSlope(r);
        if (!slope) return std::nullopt;
        return r > 0.0 ? glm::dvec2(*slope * x / r, *slope * y / r) : glm::dvec2(0.0);
    }
    // z = u / (1 + s), u = cx x^2 + cy y^2, s = sqrt(D), D = 1 - ax x^2 - ay y^2 (a = (1 + k) c^2):
    // dz/dx = (2 cx x (1 + s) + u ax x / s) / (1 + s)^2, and the same in y.
    const double cx = curvatureX(), cy = curvatureY();
    const double ax = (1.0 + conicOfX()) * cx * cx, ay = (1.0 + conicOfY()) * cy * cy;
    const double disc = 1.0 - ax * x * x - ay * y * y;
    if (disc <= 0.0) return std::nullopt; // the rim of a closed conic section: the slope is infinite
    const double s = std::sqrt(disc), u = cx * x * x + cy * y * y, d = (1.0 + s) * (1.0 + s);
    return glm::dvec2((2.0 * cx * x * (1.0 + s) + u * ax * x / s) / d, (2.0 * cy * y * (1.0 + s) + u * ay * y / s) / d);
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

namespace {

constexpr int kRangeAngles = 64; // over a quarter turn: both sections of a surface are even

void widen(std::optional<std::pair<double, double>>& range, double z) {
    if (!range) range.emplace(z, z);
    range->first = std::min(range->first, z);
    range->second = std::max(range->second, z);
}

} // namespace

std::optional<std::pair<double, double>> Surface::sagRange(double r) const {
    constexpr int kRadii = 128;
    std::optional<std::pair<double, double>> range;
    const int angles = rotationallySymmetric() ? 1 : kRangeAngles + 1;
    for (int a = 0; a < angles; ++a) {
        const double phi = angles == 1 ? 0.0 : 0.5 * std::numbers::pi * a / kRangeAngles;
        for (int k = 0; k <= kRadii; ++k) {
            const double rho = r * k / kRadii;
            const auto z = rotationallySymmetric() ? sag(rho) : sagAt(rho * std::cos(phi), rho * std::sin(phi));
            if (!z) break;
            widen(range, *z);
        }
    }
    return range;
}

std::optional<std::pair<double, double>> Surface::rimRange(double r) const {
    if (rotationallySymmetric()) {
        const auto z = sag(r);
        return z ? std::optional(std::pair(*z, *z)) : std::nullopt;
    }
    std::optional<std::pair<double, double>> range;
    for (int a = 0; a <= kRangeAngles; ++a) {
        const double phi = 0.5 * std::numbers::pi * a / kRangeAngles;
        const auto z = sagAt(r * std::cos(phi), r * std::sin(phi));
        if (!z) return std::nullopt;
        widen(range, *z);
    }
    return range;
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
    if (!rotationallySymmetric()) {
        // n ∝ (-dz/dx, -dz/dy, 1).
        const auto g = sagGradient(local.x, local.y);
        if (!g || !std::isfinite(g->x) || !std::isfinite(g->y)) return std::nullopt;
        return glm::normalize(glm::dvec3(-g->x, -g->y, 1.0));
    }
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
