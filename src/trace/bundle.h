#pragma once
// Ray bundles for a light source at infinity: parallel rays on an N x N cell-centred grid in the
// entrance-pupil plane (z = paraxial entrance pupil at the d line), started in front of the lens.
//
// Field convention: a source at field angle theta and azimuth phi sends rays whose transverse
// direction is chosen so that its direct image lands at sensor position r (-sin phi, cos phi), r > 0:
// phi = 0 puts the image at +y, phi = 90 deg at -x (counter-clockwise from +y). Every launched ray
// stands for one grid cell of area cellArea (mm^2 in the pupil plane).

#include "optics/lens.h"
#include "optics/real_ray.h"

#include <glm/vec3.hpp>

#include <vector>

namespace ff::trace {

struct Field {
    double angleRad = 0.0;
    double azimuthRad = 0.0;
};

struct Bundle {
    int n = 0;                 ///< grid size per side
    double x0 = 0.0, y0 = 0.0; ///< pupil-plane corner of the grid (mm)
    double cell = 0.0;         ///< cell side (mm); cells are square
    double cellArea = 0.0;
    std::vector<optics::Ray> rays; ///< n*n rays, row-major (row = y index)
    std::vector<char> launched;    ///< 0 for grid points outside the sampled region
};

/// Unit direction of the rays of a field (see the convention above); eflSign = sign of the EFL
/// (a negative lens forms its virtual image on the other side).
glm::dvec3 fieldDirection(const Field& f, double eflSign);

/// The paraxial entrance pupil (d line) that bundles are laid out in.
struct PupilFrame {
    double z = 0.0;      ///< pupil plane, from the first vertex
    double radius = 0.0; ///< paraxial entrance-pupil radius
    double startZ = 0.0; ///< where rays are started (in front of the first surface)
    double eflSign = 1.0;
    double frontRadius = 0.0; ///< first surface's clear aperture (0 if not given)
};
PupilFrame pupilFrame(const optics::Lens& lens);

/// A grid of n x n rays over the square [cx - h, cx + h] x [cy - h, cy + h] of the pupil plane.
Bundle gridBundle(const PupilFrame& frame, const Field& field, int n, double cx, double cy, double halfSize,
                  bool discOnly);

} // namespace ff::trace
