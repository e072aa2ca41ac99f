#include "trace/colour.h"

#include <cmath>

namespace ff::trace {

std::array<double, 3> cie1931(double l) {
    // Wyman, Sloan & Shirley 2013, multi-lobe piecewise Gaussian fit (their equation 2).
    auto g = [l](double mu, double s1, double s2) {
        const double t = (l - mu) / (l < mu ? s1 : s2);
        return std::exp(-0.5 * t * t);
    };
    const double x = 1.056 * g(599.8, 37.9, 31.0) + 0.362 * g(442.0, 16.0, 26.7) - 0.065 * g(501.1, 20.4, 26.2);
    const double y = 0.821 * g(568.8, 46.9, 40.5) + 0.286 * g(530.9, 16.3, 31.1);
    const double z = 1.217 * g(437.0, 11.8, 36.0) + 0.681 * g(459.0, 26.0, 13.8);
    return {x, y, z};
}

std::array<double, 3> linearSrgb(double lambdaNm) {
    const auto [X, Y, Z] = cie1931(lambdaNm);
    // XYZ -> linear sRGB (IEC 61966-2-1).
    return {3.2406 * X - 1.5372 * Y - 0.4986 * Z, -0.9689 * X + 1.8758 * Y + 0.0415 * Z,
            0.0557 * X - 0.2040 * Y + 1.0570 * Z};
}

void colourWeights(int n, std::vector<double>& lambdas, std::vector<std::array<double, 3>>& weights) {
    lambdas.clear();
    weights.clear();
    if (n == 0) {
        lambdas = {650.0, 550.0, 450.0};
        weights = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
        return;
    }
    std::array<double, 3> white{};
    for (int i = 0; i < n; ++i) {
        const double l = 400.0 + 300.0 * (i + 0.5) / n;
        const std::array<double, 3> rgb = linearSrgb(l);
        lambdas.push_back(l);
        weights.push_back(rgb);
        for (int c = 0; c < 3; ++c) white[c] += rgb[c];
    }
    for (auto& w : weights)
        for (int c = 0; c < 3; ++c) w[c] /= white[c];
}

} // namespace ff::trace
