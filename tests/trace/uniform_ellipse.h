#pragma once
// The image a uniform elliptical patch of light makes on a frame, written independently of the
// rasterisers: the expected ghost of the closed-form tests (a plate's disc, a cylinder's ellipse).

#include "trace/flare_raster.h"

#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace ff::test {

/// Flux per pixel (row-major) of `flux` spread uniformly over the ellipse (x / ax)^2 + (y / ay)^2 < 1
/// on the sensor (mm, centred on the axis): each pixel's area inside it, found by 64 x 64 point
/// samples where the rim may cross the pixel and taken as 0 or 1 elsewhere.
inline std::vector<double> uniformEllipse(const trace::ImageFrame& frame, double ax, double ay, double flux) {
    const double pitch = frame.pitchMm, margin = 2.0 * pitch / std::min(ax, ay);
    auto rho = [&](glm::dvec2 p) { return std::hypot(p.x / ax, p.y / ay); };
    std::vector<double> out(static_cast<std::size_t>(frame.width) * frame.height, 0.0);
    for (int j = 0; j < frame.height; ++j)
        for (int i = 0; i < frame.width; ++i) {
            const double centre = rho(frame.pixelToSensor(i + 0.5, j + 0.5));
            double inside = centre < 1.0 - margin ? 1.0 : 0.0;
            if (std::abs(centre - 1.0) <= margin) {
                int hits = 0;
                for (int b = 0; b < 64; ++b)
                    for (int a = 0; a < 64; ++a)
                        hits += rho(frame.pixelToSensor(i + (a + 0.5) / 64, j + (b + 0.5) / 64)) < 1.0;
                inside = hits / 4096.0;
            }
            out[static_cast<std::size_t>(j) * frame.width + i] =
                flux * inside * pitch * pitch / (std::numbers::pi * ax * ay);
        }
    return out;
}

/// How channel c of an interleaved RGB image agrees with `expected`: the relative L2 error, the
/// channel's sum and its most negative pixel.
struct Agreement {
    double relativeL2 = 0.0, sum = 0.0, lowest = 0.0;
};
inline Agreement agreement(const std::vector<float>& rgb, int c, const std::vector<double>& expected) {
    double d2 = 0.0, e2 = 0.0;
    Agreement a;
    for (std::size_t p = 0; p < expected.size(); ++p) {
        const double v = rgb[p * 3 + static_cast<std::size_t>(c)];
        d2 += (v - expected[p]) * (v - expected[p]);
        e2 += expected[p] * expected[p];
        a.sum += v;
        a.lowest = std::min(a.lowest, v);
    }
    a.relativeL2 = std::sqrt(d2 / e2);
    return a;
}

} // namespace ff::test
