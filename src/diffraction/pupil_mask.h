#pragma once
// Dust, scratches and other dirt on the front element, as the iris's pupil sees it: a transmittance
// multiplying the iris in the pupil function, so that its diffraction (dust's rings, a scratch's
// streak across it) comes out of the same PSF (docs/diffraction.md, "Dirt").

#include <cstdint>
#include <string>
#include <vector>

namespace ff::diffraction {

/// Transmittance in [0, 1] on a square raster over the square around the iris's circumscribed
/// circle: sample (i, j) at pupil coordinates u = (2 (i + 1/2) / size - 1), v = (1 - 2 (j + 1/2) / size),
/// in units of the iris's circumradius (rows top to bottom, +v up). 1 outside it; empty: clean.
struct PupilMask {
    int size = 0;
    std::vector<float> transmittance; ///< size x size
    /// What made it, for the PSF cache: "dirt SEED,DENSITY" or "mask SIZE HASH" (of the values).
    std::string key;

    bool empty() const { return size == 0; }
    /// Bilinear between the samples' centres, at (u, v) in units of the circumradius.
    double at(double u, double v) const;
};

/// Procedural dirt, the same raster for the same seed and density on any machine: about 80 x density
/// dust specks (opaque to half-transparent discs of 0.3 % to 2 % of the circumradius) and 3 x density
/// scratches (thin polylines, 0.1 % to 0.3 % of the circumradius wide, 30 % to 90 % long). Density
/// must be finite, above 0 and at most 100 (ff::Error, Usage).
PupilMask proceduralDirt(std::uint64_t seed, double density, int size = 1024);

/// A mask from an image's values (`channels` interleaved per pixel; luminance from the channels r,
/// g, b, Rec. 709 weights, or the single channel r when g and b are negative), clamped to [0, 1]; the
/// image's centred square (its shorter side) spans the iris's circumscribed circle. Non-finite
/// values are refused (ff::Error, Input, naming `name`).
PupilMask maskFromImage(const std::vector<float>& pixels, int width, int height, int channels, int r, int g, int b,
                        const std::string& name);

/// The product of two masks (either may be empty), on the larger's raster.
PupilMask combine(const PupilMask& a, const PupilMask& b);

} // namespace ff::diffraction
