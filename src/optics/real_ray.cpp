#include "optics/real_ray.h"

#include "core/error.h"
#include "optics/gradient_index.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace ff::optics {

namespace {

// Root of a t^2 + 2 B t + C = 0 on the branch through the vertex: the one that tends to the
// plane solution -C / (2B) as the curvature goes to zero (the larger-magnitude denominator).
std::optional<double> vertexBranchRoot(double a, double B, double C) {
    const double disc = B * B - a * C;
    if (disc < 0.0) return std::nullopt;
    const double q = -B + (B <= 0.0 ? std::sqrt(disc) : -std::sqrt(disc));
    if (q == 0.0) return std::nullopt;
    return C / q;
}

// Where the ray p + t d (p on the vertex plane) meets an anamorphic surface: Newton on
// f(t) = z(t) - sag(x(t), y(t)), f'(t) = d.z - grad(sag) . (d.x, d.y), from the vertex plane (t = 0).
// The vertex plane is the sag's tangent plane, so for lens rays the first root Newton reaches from it
// is the one on the vertex's branch.
std::optional<double> anamorphicRoot(const Surface& s, const glm::dvec3& p, const glm::dvec3& d) {
    if (!s.hasExactShape())
        throw Error(ErrorKind::Input, s.origin,
                    std::string("a ") + toString(s.shape) +
                        " surface has no exact shape to trace (give it as biconic)");
    double t = 0.0;
    for (int it = 0; it < 60; ++it) {
        const glm::dvec3 q = p + t * d;
        const auto z = s.sagAt(q.x, q.y);
        const auto g = s.sagGradient(q.x, q.y);
        if (!z || !g) return std::nullopt;
        const double fp = d.z - (g->x * d.x + g->y * d.y);
        if (fp == 0.0 || !std::isfinite(fp)) return std::nullopt;
        const double step = (q.z - *z) / fp;
        t -= step;
        if (std::abs(step) < 1e-13 * (1.0 + std::abs(t))) return t;
    }
    return std::nullopt;
}

} // namespace

std::optional<SurfaceHit> intersectSurface(const Surface& s, double vertexZ, const Ray& ray, double tMin) {
    auto hit = intersectSurfacePoint(s, vertexZ, ray, tMin);
    if (!hit) return std::nullopt;
    auto n = s.normal(glm::dvec3(hit->point.x, hit->point.y, hit->point.z - vertexZ));
    if (!n) return std::nullopt;
    hit->normal = *n;
    return hit;
}

std::optional<SurfaceHit> intersectSurfacePoint(const Surface& s, double vertexZ, const Ray& ray, double tMin) {
    const glm::dvec3& d = ray.dir;
    if (std::abs(d.z) < 1e-12) return std::nullopt; // travelling within a vertex plane: not a lens ray
    // Transfer to the vertex tangent plane first (Spencer & Murty), so that the quadratic's
    // vertex-branch root is the right one however far away the ray starts.
    const double t0 = (vertexZ - ray.origin.z) / d.z;
    const glm::dvec3 p(ray.origin.x + t0 * d.x, ray.origin.y + t0 * d.y, 0.0);
    if (!s.rotationallySymmetric()) {
        auto t = anamorphicRoot(s, p, d);
        if (!t || t0 + *t <= tMin) return std::nullopt;
        const glm::dvec3 local = p + *t * d;
        return SurfaceHit{t0 + *t, glm::dvec3(local.x, local.y, local.z + vertexZ), glm::dvec3(0.0)};
    }
    const double c = s.curvature(), k1 = 1.0 + s.conic;
    // Conic: c (x^2 + y^2 + (1 + k) z^2) - 2 z = 0, from p (z = 0) along d.
    const double a = c * (d.x * d.x + d.y * d.y + k1 * d.z * d.z);
    const double B = c * (p.x * d.x + p.y * d.y) - d.z;
    const double C = c * (p.x * p.x + p.y * p.y);
    auto t = vertexBranchRoot(a, B, C);
    if (!t) return std::nullopt;

    if (s.isAspheric()) {
        // Newton on f(t) = z(t) - sag(r(t)), f'(t) = dz - sag'(r) dr/dt.
        double tt = *t;
        bool converged = false;
        for (int it = 0; it < 60; ++it) {
            const glm::dvec3 q = p + tt * d;
            const double r = std::sqrt(q.x * q.x + q.y * q.y);
            auto z = s.sag(r);
            auto dz = s.sagSlope(r);
            if (!z || !dz) return std::nullopt;
            const double f = q.z - *z;
            const double drdt = r > 0.0 ? (q.x * d.x + q.y * d.y) / r : 0.0;
            const double fp = d.z - *dz * drdt;
            if (fp == 0.0) return std::nullopt;
            const double step = f / fp;
            tt -= step;
            if (std::abs(step) < 1e-13 * (1.0 + std::abs(tt))) {
                converged = true;
                break;
            }
        }
        if (!converged) return std::nullopt;
        t = tt;
    }
    if (t0 + *t <= tMin) return std::nullopt;
    const glm::dvec3 local = p + *t * d;
    return SurfaceHit{t0 + *t, glm::dvec3(local.x, local.y, local.z + vertexZ), glm::dvec3(0.0)};
}

bool clipped(const Surface& s, const glm::dvec3& point) {
    return s.semiAperture > 0.0 && point.x * point.x + point.y * point.y > s.semiAperture * s.semiAperture;
}

std::optional<glm::dvec3> refract(const glm::dvec3& d, const glm::dvec3& nIn, double n1, double n2) {
    glm::dvec3 n = nIn;
    double cosi = -glm::dot(n, d);
    if (cosi < 0.0) {
        n = -n;
        cosi = -cosi;
    }
    const double eta = n1 / n2;
    const double k = 1.0 - eta * eta * (1.0 - cosi * cosi);
    if (k < 0.0) return std::nullopt;
    return glm::normalize(eta * d + (eta * cosi - std::sqrt(k)) * n);
}

glm::dvec3 reflect(const glm::dvec3& d, const glm::dvec3& n) {
    return d - 2.0 * glm::dot(d, n) * n;
}

const char* toString(RayStatus s) {
    switch (s) {
    case RayStatus::Ok:
        return "ok";
    case RayStatus::Missed:
        return "missed";
    case RayStatus::Clipped:
        return "clipped";
    case RayStatus::TotalInternalReflection:
        return "total internal reflection";
    case RayStatus::Blocked:
        return "blocked";
    }
    return "?";
}

RealTraceResult traceReal(const Lens& lens, double lambdaNm, Ray ray, bool clip, const GradientSettings& gradient) {
    double z = 0.0, zBefore = 0.0;
    for (std::size_t i = 0; i < lens.surfaces.size(); ++i) {
        const Surface& s = lens.surfaces[i];
        // The medium before: straight, or the curved path through a graded element (optics/gradient_index.h).
        std::optional<SurfaceHit> hit;
        double n1 = lens.mediumBefore(i).index(lambdaNm);
        const Medium* graded = i > 0 && lens.surfaces[i - 1].medium.gradient ? &lens.surfaces[i - 1].medium : nullptr;
        if (graded) {
            const GradientField field(n1, *graded->gradient, lambdaNm, zBefore);
            const double barrel = clip ? std::max(lens.surfaces[i - 1].semiAperture, s.semiAperture) : 0.0;
            if (const auto g =
                    propagate(field, ray.origin, ray.dir, lens.surfaces[i - 1], zBefore, s, z, barrel, gradient)) {
                hit = SurfaceHit{g->length, g->point, g->normal};
                ray.dir = g->dir;
                n1 = g->index;
            }
        } else {
            hit = intersectSurface(s, z, ray);
        }
        if (!hit) return {RayStatus::Missed, i, ray};
        if (clip && clipped(s, hit->point)) return {RayStatus::Clipped, i, ray};
        const double n2 =
            s.medium.gradient
                ? GradientField(s.medium.index(lambdaNm), *s.medium.gradient, lambdaNm, z).index(hit->point)
                : s.medium.index(lambdaNm);
        auto dir = refract(ray.dir, hit->normal, n1, n2);
        if (!dir) return {RayStatus::TotalInternalReflection, i, ray};
        ray = {hit->point, *dir};
        zBefore = z;
        z += s.thickness;
    }
    return {RayStatus::Ok, lens.surfaces.size(), ray};
}

double realRayEfl(const Lens& lens, double lambdaNm, double height, Section section) {
    const bool x = section == Section::X;
    const Ray in{{x ? height : 0.0, x ? 0.0 : height, -1.0}, {0.0, 0.0, 1.0}};
    GradientSettings gradient;
    gradient.tolerance = 1e-8 * std::abs(height);
    const RealTraceResult r = traceReal(lens, lambdaNm, in, false, gradient);
    const double out = x ? r.ray.dir.x : r.ray.dir.y;
    if (r.status != RayStatus::Ok || out == 0.0)
        throwRuntimeError("a real ray at height " + std::to_string(height) + " mm did not reach image space (" +
                          toString(r.status) + " at surface " + std::to_string(r.surface + 1) + ")");
    // In image space of index n', the paraxial EFL is -y / (n' u'); the real-ray analogue uses sin U'.
    return -height / (lens.surfaces.back().medium.index(lambdaNm) * out);
}

} // namespace ff::optics
