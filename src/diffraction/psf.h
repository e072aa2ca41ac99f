#pragma once
// The lens's point-spread function from its iris, by FFT (Fraunhofer diffraction; docs/diffraction.md).
//
// A light at infinity is focused by an aberration-free lens whose exit pupil is the iris's shape. In
// image space, with N the working f-number (exit pupil to sensor over the pupil's diameter D) and s the
// pupil coordinate in units of D, the irradiance on the sensor at x (mm) is
//
//     I(x) = flux x |P^(x / (lambda N))|^2 / (lambda N)^2 / A,     P^(nu) = Int P(s) exp(-2 pi i s.nu) ds,
//
// A = the pupil's area in units of D^2 (so that Int I = flux, Parseval). P^ is computed by an FFT of
// the pupil sampled on a transform x transform grid, Q samples across D (zero padding around it): the
// intensity's samples are spaced lambda N Q / transform apart. Q is chosen per wavelength so that this
// spacing is a pixel over an integer S and at most lambda N / 2 (the intensity is band-limited at
// 1 / (lambda N), so its samples hold it whole). The PSF is binned over pixels, not point-sampled (the
// Airy core of a 50 mm lens at f/8 is smaller than a 1080p pixel): the intensity's transform times the
// pixel's sinc, back, read at the pixels' centres: exactly the irradiance integrated over each pixel.
// Each wavelength is its own transform (the pattern scales with lambda; rescaling one transform would
// need resampling across the fringes). RGB: the wavelengths' PSFs weighted by the CIE 1931 matching
// functions through linear sRGB (trace::colourWeights), negatives clipped, each channel's weights
// summing to 1.

#include "diffraction/aperture.h"
#include "diffraction/far_field.h"
#include "diffraction/pupil_mask.h"
#include "optics/lens.h"

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ff::diffraction {

/// The lens's aperture at its working opening (d line): the stop's blades and rotation, and the
/// f-number from the paraxial exit pupil (the header's f-number where the exit pupil is at infinity).
Aperture apertureOf(const optics::Lens& lens);

/// Optical path difference over the exit pupil, mm, at pupil coordinates (u, v) in units of the
/// iris's equal-area radius (+u right, +v up; u^2 + v^2 <= 1 on a round iris). A defocus is
/// W020 (u^2 + v^2); its rays spread over a disc of radius 4 N W020 on the sensor.
using Wavefront = std::function<double(double u, double v)>;

/// Whether the rest of the lens lets the iris's light through at pupil point (u, v): vignetting by
/// the other elements' clear apertures. Empty: all of the iris.
using Transmission = std::function<bool(double u, double v)>;

/// The pupil function at one wavelength beyond the bare iris: its wavefront and vignetting.
struct PupilFunction {
    Wavefront opd;     ///< empty: aberration-free
    Transmission open; ///< empty: unvignetted
    /// The largest |grad W| over the open pupil, mm per unit of u: the rays land up to 2 N of it
    /// from the light, so the transform is made large enough to sample the phase and hold the spot.
    double maxSlopeMm = 0.0;
};

/// One wavelength's PSF sampled (not binned) on a square grid centred on the light.
struct SampledPsf {
    int size = 0;              ///< samples per side; the light at sample (size / 2, size / 2)
    double spacingMm = 0.0;    ///< between samples on the sensor
    std::vector<double> value; ///< share of the flux per sample x spacing^2 (row-major, +y up); sums to 1
};

/// The PSF at lambdaNm with samples spacingMm apart on a transform x transform grid (even, 64 to
/// 16384). The pupil's diameter takes Q = transform x spacing / (lambda N) samples: refused
/// (ff::Error, Usage) when Q is under 32 (too few for the iris's shape) or over transform / 2 (the
/// intensity, band-limited at twice the pupil, would alias). With a wavefront the pupil function is
/// the iris x open x exp(2 pi i W / lambda) (a complex transform); its phase must change by under
/// pi from one pupil sample to the next (refused otherwise, ff::Error Input): the rays then land
/// within half a period of the light. A mask (dirt) multiplies the iris.
SampledPsf sampledPsf(const Aperture& aperture, double lambdaNm, double spacingMm, int transform,
                      const Wavefront& wavefront = {}, const Transmission& open = {}, const PupilMask* mask = nullptr);

struct PsfSettings {
    double pitchMm = 0.0;              ///< the sensor's pixel pitch
    std::vector<double> wavelengthsNm; ///< empty: 8 over 400-700 nm
    int transform = 2048;              ///< FFT size per side, per wavelength (at least: see pupil)
    /// Per wavelength, the pupil function beyond the bare iris (the traced wavefront and vignetting,
    /// wavefront.h); none: the aberration-free PSF. The transform grows with its maxSlopeMm.
    std::function<PupilFunction(double lambdaNm)> pupil;
    /// Dirt on the front element multiplying the iris (none: clean). Its diffraction reaches the
    /// transform's reach (K / 4 pixels, the shortest wavelength's), tapered from 0.3 of it.
    std::shared_ptr<const PupilMask> mask;
};

/// The RGB PSF binned over the sensor's pixels: the transform's near field in a square, the far
/// field (closed form) beyond it, to any distance.
struct Psf {
    int radius = 0;                            ///< (2 radius + 1)^2 pixels; the light's own pixel at the centre
    std::array<std::vector<float>, 3> channel; ///< share of the light's flux per pixel, rows top to bottom
    FarField far;                              ///< beyond the square; empty: nothing there
    std::vector<double> wavelengthsNm;
    std::vector<int> binning; ///< per wavelength: samples per pixel side (S)
    /// Largest share of a channel's flux that the square and the far field together miss (or
    /// exceed): kept in the light's own pixel, so that each channel sums to 1.
    double outside = 0.0;
    double edge =
        0.0; ///< largest pixel where the far field takes over (0.5 of a wavelength's reach and beyond) over the centre
    int width() const { return 2 * radius + 1; }
    float at(int c, int dx, int dy) const { ///< offset (dx right, dy down) from the light's pixel, within the square
        return channel[c][static_cast<std::size_t>(dy + radius) * width() + (dx + radius)];
    }
};

/// Bins each wavelength's PSF over pixels of settings.pitchMm (S x S samples per pixel, the samples
/// at most lambda N / 2 apart; the transform rounded to a whole number K of pixels per period) and
/// combines them into RGB. The transform's near field is kept to a fifth of its reach (K / 4 pixels;
/// with a pupil function, 0.6 of it: the aberrated spot lies within it), less
/// the neighbouring periods' far fields (which the transform folds onto it), and blends (cos^2) into
/// the far field by 0.4 (0.9) of that reach; the far field (FarField) goes on from there to any distance.
/// Where a pixel spans more than 16384 / 4 samples (over 2 000 lambda N: a tiny plate on a large
/// sensor) the near field is the light's own pixel. Each channel sums to 1 over the plane
/// (Psf::outside).
Psf pixelPsf(const Aperture& aperture, const PsfSettings& settings);

} // namespace ff::diffraction
