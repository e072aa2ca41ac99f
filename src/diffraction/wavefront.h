#pragma once
// The direct path's wavefront at a light's field, traced exactly (what lens-design tools feed their
// FFT PSF).
//
// Rays of one field leave a plane wavefront in object space and cross the lens with every aperture
// open; each ray's optical path length sum(n |step|) is taken from that plane to the reference sphere:
// centred on the chief ray's point on the sensor (the light's image, trace::fieldForSensorPoint's), its
// radius the chief ray's distance from the paraxial exit pupil's plane to that point. The optical path
// difference W = OPL(ray) - OPL(chief), mm, is a function of the ray's point in the iris's plane
// over the working stop radius: the pupil coordinates of diffraction::Wavefront (the exit pupil being
// the stop's erect image; +x, +y those of the sensor). W is fitted over the traced rays by products of
// Chebyshev polynomials of total degree <= 10, so that it can be read anywhere inside the iris.
//
// With this sign a ray leaving the pupil at radius-unit coordinates (u, v) lands 2 N grad W from the
// sphere's centre (a wave converging to a point shifted by dx has W = dx u D / (2 R)), which is
// also where the Fraunhofer integral of psf.h puts the PSF's centroid: the geometric spot's.

#include "diffraction/psf.h"
#include "optics/lens.h"

#include <glm/vec2.hpp>

#include <functional>
#include <limits>
#include <vector>

namespace ff::diffraction {

struct TracedWavefront {
    /// W (mm over psf.h's pupil coordinates), the vignetting (where a fitted hit point falls outside
    /// another surface's clear aperture) and W's largest slope over the open pupil.
    PupilFunction pupil;
    glm::dvec2 imageMm{0.0};     ///< the chief ray's point on the sensor
    double rmsMm = 0.0;          ///< RMS of W over the traced rays inside the iris and let through (mean removed)
    double peakToValleyMm = 0.0; ///< over the same rays
    double fitResidualMm = 0.0;  ///< RMS of the fit's residual over them
    double vignetted = 0.0;      ///< share of the iris's rays another aperture blocks
    std::size_t rays = 0;        ///< traced rays inside the iris, let through to the sensor
};

/// The wavefront of a light at field (angleRad, azimuthRad) (trace::Field's convention: the image at
/// r (-sin az, cos az)) at lambdaNm, on the sensor plane sensorZ (NaN: the lens's own). The reference
/// sphere is centred on referenceMm where given (one wavelength's chief point for all: the others'
/// lateral colour becomes a tilt), else on this wavelength's chief ray. `grid` rays per side over the
/// iris. Throws ff::Error (Input) when the chief ray cannot be aimed through the stop's centre, fewer
/// than half the rays inside the iris reach the sensor, or the lens blocks them all.
TracedWavefront tracedWavefront(const optics::Lens& lens, double angleRad, double azimuthRad, double lambdaNm,
                                double sensorZ = std::numeric_limits<double>::quiet_NaN(),
                                const glm::dvec2* referenceMm = nullptr, int grid = 48);

/// PsfSettings::pupil for a light whose image is at sensor point (xMm, yMm): each wavelength's
/// traced wavefront, all referenced to the d line's chief point there (so lateral colour is a tilt
/// and the RGB PSF stays centred on the light's pixel at the d line). Throws ff::Error (Input) as
/// trace::fieldForSensorPoint and tracedWavefront do.
std::function<PupilFunction(double lambdaNm)> tracedPupil(const optics::Lens& lens, double xMm, double yMm,
                                                          double sensorZ = std::numeric_limits<double>::quiet_NaN());

} // namespace ff::diffraction
