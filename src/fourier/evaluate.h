#pragma once
// Evaluating the Fourier series on the frame's pixels. A pixel's value is the series integrated
// over the pixel: term n is scaled by sinc(n w / 2) (the transform of the one-pixel box) and
// evaluated at the pixel centre, so an evaluated image keeps the flux of a directly drawn one.
//
// Matrix form: with X = [kappa_n c_n(x_i); kappa_n s_n(x_i)] (2N x W) and Y likewise (2M x H),
// image = X^T (Z Y): two float32 GEMMs per channel, 4NMH + 2NWH multiply-adds, whatever the number
// of ghosts. FFT form: the coefficients placed on the period's Px x Py grid and one real inverse
// FFT (FFTW, float32) per channel, of which the frame is the top-left window.

#include "fourier/aggregate.h"

namespace ff::fourier {

/// The basis of one axis, 2 terms x pixels, row-major: rows n < terms hold
/// kappa_n sinc(n w / 2) cos(n w (i + 1/2)), rows terms + n the same with sin (w = 2 pi / period).
std::vector<float> seriesBasis(int terms, int pixels, double period);

/// Whether evaluate() replaces the image's values or adds the series to them.
enum class Write { Replace, Add };

/// Writes the series into image (its size is the frame's). Evaluation::Auto = Matrix.
void evaluate(const Coefficients& z, Evaluation method, FlareImage& image, Write write = Write::Replace);

} // namespace ff::fourier
