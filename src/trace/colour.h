#pragma once
// Light's colour: the CIE 1931 observer, linear sRGB, and the wavelengths a flare is traced at with
// their weights (the traced renderer, the PSFs and the shaped ghosts share them).

#include <array>
#include <vector>

namespace ff::trace {

/// Wavelengths and their linear-sRGB weights (one row of 3 per wavelength) for a colour mode.
void colourWeights(int spectralSamples, std::vector<double>& wavelengthsNm,
                   std::vector<std::array<double, 3>>& weights);

/// CIE 1931 2-degree colour matching functions (x, y, z) at lambdaNm, analytic fit.
std::array<double, 3> cie1931(double lambdaNm);

/// The colour of a unit of light at lambdaNm in linear sRGB (CIE 1931 through IEC 61966-2-1's matrix);
/// out-of-gamut wavelengths have negative components.
std::array<double, 3> linearSrgb(double lambdaNm);

} // namespace ff::trace
