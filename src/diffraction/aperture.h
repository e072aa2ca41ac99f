#pragma once
// The diffracting aperture, as the PSF (psf.h) and its far field (far_field.h) see it.

namespace ff::diffraction {

/// The diffracting aperture: the iris's shape in the sensor's frame (+x right, +y up) and the
/// image-space working f-number.
struct Aperture {
    int blades = 0;           ///< straight blades; < 3: circular
    double rotationRad = 0.0; ///< as trace::Iris: the blades' edge normals at rotation + (k + 1/2) 2 pi / blades
    double fNumber = 0.0;     ///< working f-number: exit pupil to sensor over the exit pupil's diameter
};

} // namespace ff::diffraction
