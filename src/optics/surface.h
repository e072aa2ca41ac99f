#pragma once
// One refracting surface of a lens prescription, with its exact shape. Lengths in mm; the local
// frame has its origin at the surface vertex, +z along the axis towards the sensor.
//
// Sag (z of the surface at radial distance r from the axis):
//   z(r) = c r^2 / (1 + sqrt(1 - (1 + k) c^2 r^2)) + A4 r^4 + A6 r^6 + ...
// with curvature c = 1/radius (0 for a flat surface), conic constant k and even-asphere terms.
//
// An anamorphic surface has a curvature and a conic per section (docs/lens-format.md): the biconic
//   z(x, y) = (cx x^2 + cy y^2) / (1 + sqrt(1 - (1 + kx) cx^2 x^2 - (1 + ky) cy^2 y^2)),
// whose y-z section is the row's radius and conic and whose x-z section is radiusX and conicX; a
// cylinder is the case of one flat section (cyl_x: its axis along x, curved in y; cyl_y: its axis
// along y, curved in x), exact as a biconic.

#include "core/error.h"
#include "optics/coating_spec.h"
#include "optics/medium.h"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <optional>
#include <utility>
#include <vector>

namespace ff::optics {

/// Cross-section shapes: FlareSim-family files' 7th/8th column (sph, cyl_x, cyl_y, toric) and our
/// biconic. Only Spherical (with its conic and asphere) is rotationally symmetric; Toric (a torus)
/// is read and kept but has no exact shape here, and stages that need symmetry refuse the others.
enum class SurfaceShape { Spherical, CylinderX, CylinderY, Toric, Biconic };
const char* toString(SurfaceShape s);

/// A plane through the axis, for first-order data of anamorphic lenses: the y-z section (the one of
/// a surface's `radius`, and the meridional plane of a rotationally symmetric lens) or the x-z one.
enum class Section { Y, X };

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
    double radiusX = 0.0;  ///< Biconic: the x-z section's vertex radius, mm (0 = flat)
    double conicX = 0.0;   ///< Biconic: the x-z section's conic constant
    SourceLocation origin; ///< where it was defined (for messages)

    double curvature() const { return radius == 0.0 ? 0.0 : 1.0 / radius; }
    bool isFlat() const { return radius == 0.0 && asphere.empty(); }
    bool isAspheric() const { return !asphere.empty(); }
    bool rotationallySymmetric() const { return shape == SurfaceShape::Spherical; }

    /// The curvature and conic of the x-z and y-z sections (both curvature() and conic where
    /// rotationally symmetric; Toric: its y-z section in both, as the first-order data take it).
    double curvatureX() const;
    double curvatureY() const;
    double conicOfX() const;
    double conicOfY() const;
    /// An exact shape here: rotationally symmetric, a cylinder or a biconic (not Toric).
    bool hasExactShape() const { return shape != SurfaceShape::Toric; }

    /// Sag z(x, y) in mm of any shape with an exact one, and its partial derivatives dz/dx, dz/dy;
    /// nullopt outside the surface's domain.
    std::optional<double> sagAt(double x, double y) const;
    std::optional<glm::dvec2> sagGradient(double x, double y) const;
    /// Sag z(r) in mm; nullopt where the conic part is undefined (1 - (1+k) c^2 r^2 < 0).
    std::optional<double> sag(double r) const;
    /// The lowest and highest sag over the disc of radius r about the axis, mm (sampled: along a
    /// radius where rotationally symmetric — aspheres need not be monotonic —, over a polar grid
    /// otherwise); nullopt where the shape is undefined at the axis. Past the domain's edge the
    /// samples stop.
    std::optional<std::pair<double, double>> sagRange(double r) const;
    /// The lowest and highest sag around the rim of radius r, mm: sag(r) twice where rotationally
    /// symmetric; sampled over a quarter turn otherwise (both sections are even). nullopt where the
    /// shape is undefined somewhere on the rim.
    std::optional<std::pair<double, double>> rimRange(double r) const;
    /// dz/dr at r (same domain as sag).
    std::optional<double> sagSlope(double r) const;
    /// Unit normal, oriented towards +z, at a point on the surface given in its vertex frame
    /// (x, y, z - vertexZ); nullopt where the sag's slope is undefined. Any shape with an exact one.
    std::optional<glm::dvec3> normal(const glm::dvec3& local) const;
};

} // namespace ff::optics
