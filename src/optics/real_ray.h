#pragma once
// Exact (real) ray tracing through the analytic surfaces of a lens, in double precision: the
// geometry that every tracer shares, and the plain sequential tracer used as a test reference.
// Frame: +z along the axis, z = 0 at the first vertex, lengths in mm; directions are unit vectors.

#include "optics/gradient_index.h"
#include "optics/lens.h"

#include <glm/vec3.hpp>

#include <optional>

namespace ff::optics {

struct Ray {
    glm::dvec3 origin{0.0};
    glm::dvec3 dir{0.0, 0.0, 1.0};
};

struct SurfaceHit {
    double t = 0.0; ///< ray parameter of the hit (origin + t dir)
    glm::dvec3 point{0.0};
    glm::dvec3 normal{0.0}; ///< unit normal, oriented with a positive z component
};

/// Nearest intersection with t > tMin of the ray and the surface whose vertex is at z = vertexZ,
/// on the branch through the vertex. Spheres and conics in closed form; even aspheres by Newton
/// iteration on the sag starting from the conic solution. Ignores the semi-aperture (see clipped).
std::optional<SurfaceHit> intersectSurface(const Surface& s, double vertexZ, const Ray& ray, double tMin = -1e-9);

/// The same intersection without the normal: the ray parameter and point only (cheaper, for
/// visibility queries that test many candidate surfaces).
std::optional<SurfaceHit> intersectSurfacePoint(const Surface& s, double vertexZ, const Ray& ray, double tMin = -1e-9);

/// True when the hit lies outside the surface's clear semi-aperture (0 = unclipped).
bool clipped(const Surface& s, const glm::dvec3& point);

/// Vector Snell refraction of unit direction d at unit normal n from index n1 into n2.
/// Returns nullopt on total internal reflection. n may face either way.
std::optional<glm::dvec3> refract(const glm::dvec3& d, const glm::dvec3& n, double n1, double n2);

/// Mirror reflection of d at unit normal n.
glm::dvec3 reflect(const glm::dvec3& d, const glm::dvec3& n);

/// Why a ray was lost: it missed the next surface, fell outside its clear aperture, could not
/// refract (total internal reflection), or met another part of the lens first (Embree tracer).
enum class RayStatus { Ok, Missed, Clipped, TotalInternalReflection, Blocked };
const char* toString(RayStatus s);

struct RealTraceResult {
    RayStatus status = RayStatus::Ok;
    std::size_t surface = 0; ///< surface where the ray was lost (when status != Ok)
    Ray ray;                 ///< ray after the last surface it passed
};

/// Traces a ray from object space forward through every surface (refracting at each), checking
/// semi-apertures when clip is true. The returned ray starts at the last surface's hit point. Rays
/// through graded elements are integrated with `gradient` (optics/gradient_index.h).
RealTraceResult traceReal(const Lens& lens, double lambdaNm, Ray ray, bool clip = true,
                          const GradientSettings& gradient = {});

/// Focal length from a real ray parallel to the axis at `height` mm: -height / sin(U'), with U' the
/// final ray angle in image space. Through graded elements the integrator's tolerance is 1e-8 of the
/// height per mm of path, so its error stays far below the ray's own aberrations however small the
/// height. Throws ff::Error (Runtime) if the ray does not get through. The ray lies in `section`
/// (its height along y or x): an anamorphic lens's focal length in that section.
double realRayEfl(const Lens& lens, double lambdaNm, double height, Section section = Section::Y);

} // namespace ff::optics
