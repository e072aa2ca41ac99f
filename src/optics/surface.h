#pragma once
// One refracting surface of a lens prescription, with its exact shape. Lengths in mm; the local
// frame has its origin at the surface vertex, +z along the axis towards the sensor.
//
// Sag (z of the surface at radial distance r from the axis):
//   z(r) = c r^2 / (1 + sqrt(1 - (1 + k) c^2 r^2)) + A4 r^4 + A6 r^6 + ...
// with curvature c = 1/radius (0 for a flat surface), conic constant k and even-asphere terms.

#include "core/error.h"
#include "optics/coating_spec.h"
#include "optics/medium.h"

#include <glm/vec3.hpp>

#include <optional>
#include <vector>

namespace ff::optics {

/// Cross-section shapes found in FlareSim-family files (7th/8th column). Only Spherical is
/// rotationally symmetric; the others are read, kept, and refused by stages that need symmetry.
enum class SurfaceShape { Spherical, CylinderX, CylinderY, Toric };
const char* toString(SurfaceShape s);

struct Surface {
    double radius = 0.0;                ///< vertex radius of curvature, mm; 0 = flat
    double conic = 0.0;                 ///< conic constant k (0 sphere, -1 paraboloid)
    std::vector<double> asphere;        ///< A4, A6, A8, ...: coefficients of r^4, r^6, r^8, ...
    double thickness = 0.0;             ///< axial distance to the next surface (or the sensor), mm
    Medium medium;                      ///< medium after the surface
    double semiAperture = 0.0;          ///< clear semi-diameter, mm; 0 = not given (unclipped)
    int coatingLayers = 0;              ///< FlareSim coating column (0 bare, 1 single layer, >= 2 multi)
    std::optional<CoatingSpec> coating; ///< explicit per-surface coating; overrides the column
    bool stop = false;                  ///< this surface is the aperture stop
    bool flatStopRow = false;           ///< written as a 'stop' row (flat air-air stop) in the file
    SurfaceShape shape = SurfaceShape::Spherical;
    double radiusY = 0.0;  ///< second radius of anamorphic shapes (FlareSim 8th column)
    SourceLocation origin; ///< where it was defined (for messages)

    double curvature() const { return radius == 0.0 ? 0.0 : 1.0 / radius; }
    bool isFlat() const { return radius == 0.0 && asphere.empty(); }
    bool isAspheric() const { return !asphere.empty(); }
    bool rotationallySymmetric() const { return shape == SurfaceShape::Spherical; }

    /// Sag z(r) in mm; nullopt where the conic part is undefined (1 - (1+k) c^2 r^2 < 0).
    std::optional<double> sag(double r) const;
    /// dz/dr at r (same domain as sag).
    std::optional<double> sagSlope(double r) const;
    /// Unit normal, oriented towards +z, at a point on the surface given in its vertex frame
    /// (x, y, z - vertexZ); nullopt where the sag's slope is undefined.
    std::optional<glm::dvec3> normal(const glm::dvec3& local) const;
};

} // namespace ff::optics
