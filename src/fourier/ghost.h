#pragma once
// What the aggregator sums: axis-aligned separable ghosts in image pixels, and the RGB image they
// make. Coordinates: pixels, origin at the top-left corner of the frame, x right, y down; pixel (i, j)
// covers [i, i + 1] x [j, j + 1], so its centre is (i + 0.5, j + 0.5). A pixel's value is the flux
// that falls on it (the profile integrated over the pixel), so an image's sum is the total flux in
// the frame.

#include "fourier/coefficients.h"

#include <algorithm>
#include <array>
#include <vector>

namespace ff::fourier {

struct Ghost {
    double x = 0.0, y = 0.0;                  ///< centre, pixels
    std::array<double, 3> widthX{}, widthY{}; ///< per channel: Gaussian sigma or cos^2 half-width w, pixels
    std::array<double, 3> flux{};             ///< per channel: the profile's integral over the plane
    Shape shape = Shape::Gaussian;

    /// Peak value per unit area of channel c: flux / (integral of the unit-peak profile).
    double peak(int c) const {
        return flux[c] / (profileIntegral(shape, widthX[c]) * profileIntegral(shape, widthY[c]));
    }
    /// Half-width beyond which the profile is below 1e-8 of its peak (cos^2: its support), pixels.
    double extentX() const;
    double extentY() const;
};

/// The widest and the narrowest of a ghost's per-channel widths on one axis.
inline double widest(const std::array<double, 3>& w) {
    return std::max({w[0], w[1], w[2]});
}
inline double narrowest(const std::array<double, 3>& w) {
    return std::min({w[0], w[1], w[2]});
}

struct FlareImage {
    int width = 0, height = 0;
    std::array<std::vector<float>, 3> channel; ///< row-major planes

    FlareImage() = default;
    FlareImage(int w, int h);
    std::size_t pixels() const { return static_cast<std::size_t>(width) * height; }
    /// R, G, B interleaved per pixel.
    std::vector<float> interleaved() const;
    double sum(int c) const;
};

} // namespace ff::fourier
