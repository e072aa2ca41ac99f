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
//   - after the last step the ray is carried to the sensor plane.
// Units: mm, nm.

#include "optics/lens.h"
#include "optics/real_ray.h"
#include "trace/ghost_path.h"

#include <vector>

namespace ff::trace {

/// Per-wavelength constants of a lens, computed once: indices on both sides, clip radii.
struct LensAtWavelength {
    const optics::Lens* lens = nullptr;
    double lambdaNm = 0.0;
    std::vector<double> nBefore, nAfter, clipRadius, vertexZ; ///< per surface; clipRadius 0 = unclipped
    double sensorZ = 0.0;

    LensAtWavelength(const optics::Lens& l, double lambda);
};

struct SequentialResult {
    optics::RayStatus status = optics::RayStatus::Ok;
    std::size_t lostAtStep = 0;   ///< index into the path steps where the ray was lost
    optics::Ray ray;              ///< on the sensor plane (when Ok): origin = hit point, dir = final direction
    double weight = 0.0;          ///< product of the Fresnel/coating factors (0 when lost)
};

SequentialResult traceSequential(const LensAtWavelength& lens, const std::vector<PathStep>& steps, optics::Ray ray);

} // namespace ff::trace
