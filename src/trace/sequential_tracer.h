#pragma once
// The plain analytic sequential tracer: follows one ray along a path (direct or ghost) through the
// exact surfaces, with no acceleration structure. It is the reference the Embree tracer is tested
// against, and small enough to read as a specification:
//   - at each step, intersect the step's surface (vertex branch); a miss, or a hit outside the
//     surface's clear semi-aperture (the working opening for the stop), loses the ray there;
//   - a crossing refracts by vector Snell and multiplies the weight by 1 - R; total internal
//     reflection loses the ray;
//   - a reflection mirrors the ray and multiplies the weight by R;
//   - R is the exact unpolarised reflectance of the surface, bare or with its coating, at the ray's
//     angle of incidence and wavelength (optics/thin_film.h);
//   - through a graded-index element the ray follows its curved path (optics/gradient_index.h) to
//     the next surface, lost if it leaves the element's barrel (the larger of its surfaces' clear
//     semi-apertures), and the indices at its boundaries are the local ones;
//   - after the last step the ray is carried to the sensor plane.
// Units: mm, nm.

#include "optics/gradient_index.h"
#include "optics/lens.h"
#include "optics/real_ray.h"
#include "optics/thin_film.h"
#include "trace/aperture.h"
#include "trace/ghost_path.h"

#include <limits>
#include <optional>
#include <vector>

namespace ff::trace {

/// Per-wavelength constants of a lens, computed once: indices on both sides, clip radii, the iris.
struct LensAtWavelength {
    const optics::Lens* lens = nullptr;
    double lambdaNm = 0.0;
    std::vector<double> nBefore, nAfter, clipRadius, vertexZ; ///< per surface; clipRadius 0 = unclipped
    /// Per surface: the coating's layers at this wavelength, met from the low-index side (spec order)
    /// and from the high-index side (reversed); empty for a bare surface.
    std::vector<std::vector<optics::FilmLayer>> layersFromLow, layersFromHigh;
    /// Per surface with a coating between two homogeneous media of different index: its reflectance
    /// tabulated from the low- and the high-index side (optics::FilmReflectanceTable); empty
    /// elsewhere (applyStep computes it exactly there).
    std::vector<std::optional<optics::FilmReflectanceTable>> filmFromLow, filmFromHigh;
    std::size_t stop = 0;
    Iris iris;            ///< the stop's opening (its blades, at the working radius)
    double sensorZ = 0.0; ///< z of the sensor plane (the last thickness unless overridden)
    /// Per surface: the graded index of the space after it, placed in the lens frame (none:
    /// homogeneous), and that element's barrel radius (the larger clear semi-aperture of its two
    /// surfaces; 0: unclipped).
    std::vector<std::optional<optics::GradientField>> gradient;
    std::vector<double> barrelRadius;
    /// Per surface, for a graded space after it: the first trial step of its rays (mm), the mean step
    /// a ray parallel to the axis at half the barrel's radius takes there at the default settings (0:
    /// the integrator's own first step).
    std::vector<double> gradientStep;
    optics::GradientSettings gradientSettings;

    /// Whether the constructor tabulates the coatings' reflectance (filmFromLow / filmFromHigh; about
    /// 3 000 exact evaluations per coated surface): only traces weighted by it need them.
    enum class Films { Tabulated, Exact };

    /// sensorZ: the sensor plane; NaN = the lens's own (the last thickness).
    LensAtWavelength(const optics::Lens& l, double lambda, double sensorZ = std::numeric_limits<double>::quiet_NaN(),
                     Films films = Films::Tabulated);

    /// True when a hit point at surface s lies inside its clear aperture (the iris for the stop).
    bool insideAperture(std::size_t s, const glm::dvec3& p) const;
    /// How far a hit point at surface s lies inside its clear aperture (the iris for the stop), mm,
    /// negative outside; +infinity for an unclipped surface.
    double apertureMargin(std::size_t s, const glm::dvec3& p) const;
    /// The index just before and just after surface s at a point p on it (the local index where
    /// that side is graded).
    double indexBefore(std::size_t s, const glm::dvec3& p) const;
    double indexAfter(std::size_t s, const glm::dvec3& p) const;
};

/// No surface: a ray that starts in object space.
inline constexpr std::size_t kObjectSpace = std::numeric_limits<std::size_t>::max();

/// Where a ray that left surface `left` (kObjectSpace: from object space) next meets surface s: the
/// exact intersection of the straight ray (Embree may still find it blocked), or the end of its
/// curved path through a graded element (then ray.dir becomes the arrival direction, *graded is
/// set, and the barrel has been checked). *opticalPath, where given, receives the path's n ds
/// integral from the ray's origin. nullopt: the surface is missed, or the ray is lost inside the
/// graded element (*status, where given: Clipped where it left the barrel, else Missed). With
/// barrelMargin, the barrel does not stop the ray: *barrelMargin receives the barrel's radius less the
/// largest radius the curved path reached (mm, negative: it left the barrel; +inf on straight paths).
std::optional<optics::SurfaceHit> nextHit(const LensAtWavelength& L, std::size_t left, std::size_t s, optics::Ray& ray,
                                          bool* graded = nullptr, double* opticalPath = nullptr,
                                          optics::RayStatus* status = nullptr, double* barrelMargin = nullptr);

/// What a trace computes: the ray's fate and path with its Fresnel / coating weight, or the fate and
/// path alone (weights left at 1), for searches that only ask where light gets through.
enum class Weighting { Fresnel, None };

/// Applies one path step at an already found hit on its surface: refraction with weight 1 - R, or
/// reflection with weight R (exact Fresnel / thin film at the hit's incidence angle). Returns Ok, or
/// TotalInternalReflection when a crossing is impossible. Shared by every tracer.
optics::RayStatus applyStep(const LensAtWavelength& L, const PathStep& step, const optics::SurfaceHit& hit,
                            optics::Ray& ray, double& weight, Weighting weighting = Weighting::Fresnel);

/// Carries a ray after the last step to the sensor plane; false if it travels away from it.
bool toSensor(const LensAtWavelength& L, optics::Ray& ray);

/// Smallest ray parameter (mm) accepted for the next hit, so a ray never finds the surface it just left.
inline constexpr double kMinStep = 1e-9;

struct SequentialResult {
    optics::RayStatus status = optics::RayStatus::Ok;
    std::size_t lostAtStep = 0; ///< index into the path steps where the ray was lost
    optics::Ray ray;            ///< on the sensor plane (when Ok): origin = hit point, dir = final direction
    double weight = 0.0;        ///< product of the Fresnel/coating factors (0 when lost)
    /// The optical path (integral of n ds, mm) from the first step's hit to the last's (when Ok).
    double opticalPath = 0.0;
};

/// With openMargins (steps.size() of them), every aperture is left open: nothing clips the ray (a
/// miss or total internal reflection still ends it), and openMargins[k] receives how far step k's hit
/// lies inside its surface's aperture (LensAtWavelength::apertureMargin), NaN past the step that
/// ended the ray (the shaped ghosts clip their meshes by them); openPoints, where also given, receives step k's hit
/// point (NaN past the step that ended the ray). The barrel of a graded element is a margin too (nextHit's
/// barrelMargin), folded into the least of the margins of the step that ends the curved path, or of the
/// step that starts it where that one ends on the stop (whose margin the iris's own clipping replaces).
SequentialResult traceSequential(const LensAtWavelength& lens, const std::vector<PathStep>& steps, optics::Ray ray,
                                 Weighting weighting = Weighting::Fresnel, double* openMargins = nullptr,
                                 glm::dvec3* openPoints = nullptr);

} // namespace ff::trace
