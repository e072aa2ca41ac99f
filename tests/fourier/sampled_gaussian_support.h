#pragma once
// A Gaussian sampled as cell integrals, and its continuous coefficients in closed form: what the
// sampled-profile tests (CPU and GL) compare.

#include "fourier/sampled.h"

#include <cmath>
#include <numbers>
#include <utility>

namespace ff::fourier::testing {

// Integral over [a, b] of exp(-u^2 / 2 s^2) (the profile centred at 0).
inline double gaussianCell(double s, double a, double b) {
    const double k = 1.0 / (std::sqrt(2.0) * s);
    return s * std::sqrt(0.5 * std::numbers::pi) * (std::erf(b * k) - std::erf(a * k));
}

// A Gaussian of unit flux centred at (cx, cy), sampled as cell integrals on cells of `step` pixels
// over +-8 sigma.
inline SampledGhost sampledGaussian(double cx, double cy, double sx, double sy, double step, const double rgb[3]) {
    SampledGhost g;
    g.step = step;
    g.x0 = std::floor((cx - 8.0 * sx) / step) * step;
    g.y0 = std::floor((cy - 8.0 * sy) / step) * step;
    g.width = static_cast<int>(std::ceil(16.0 * sx / step)) + 1;
    g.height = static_cast<int>(std::ceil(16.0 * sy / step)) + 1;
    const double norm = 1.0 / (2.0 * std::numbers::pi * sx * sy);
    for (int j = 0; j < g.height; ++j) {
        const double y = g.y0 + j * step - cy;
        const double iy = gaussianCell(sy, y, y + step);
        for (int i = 0; i < g.width; ++i) {
            const double x = g.x0 + i * step - cx;
            const double v = norm * gaussianCell(sx, x, x + step) * iy;
            for (int c = 0; c < 3; ++c) g.values.push_back(static_cast<float>(rgb[c] * v));
        }
    }
    return g;
}

// The continuous Gaussian's coefficient (1 / T) Int exp(-u^2 / 2 s^2) e^{i n w (u + c)} du, as
// (cos part, sin part): s sqrt(2 pi) / T exp(-(n w s)^2 / 2) (cos, sin)(n w c).
inline std::pair<double, double> gaussianTerm(int n, double s, double c, double T) {
    const double w = 2.0 * std::numbers::pi / T,
                 g = s * std::sqrt(2.0 * std::numbers::pi) / T * std::exp(-0.5 * (n * w * s) * (n * w * s));
    return {g * std::cos(n * w * c), g * std::sin(n * w * c)};
}

} // namespace ff::fourier::testing
