// Least-squares tensor-product polynomials (tensor_polynomial.h).

#include "ghosts/tensor_polynomial.h"

#include <cmath>
#include <cstddef>
#include <utility>

namespace ff::ghosts {

std::vector<double> fitPolynomial(const std::vector<glm::dvec3>& points, int degree) {
    const int n = (degree + 1) * (degree + 1);
    const auto basis = [&](double u, double v) {
        std::vector<double> b(static_cast<std::size_t>(n));
        for (int j = 0; j <= degree; ++j)
            for (int i = 0; i <= degree; ++i)
                b[static_cast<std::size_t>(i + (degree + 1) * j)] = std::pow(u, i) * std::pow(v, j);
        return b;
    };
    // The normal equations, solved by Gaussian elimination with partial pivoting.
    const std::size_t N = static_cast<std::size_t>(n);
    std::vector<double> a(N * (N + 1), 0.0);
    for (const glm::dvec3& p : points) {
        const std::vector<double> b = basis(p.x, p.y);
        for (std::size_t r = 0; r < N; ++r) {
            for (std::size_t c = 0; c < N; ++c) a[r * (N + 1) + c] += b[r] * b[c];
            a[r * (N + 1) + N] += b[r] * p.z;
        }
    }
    for (std::size_t k = 0; k < N; ++k) {
        std::size_t pivot = k;
        for (std::size_t r = k + 1; r < N; ++r)
            if (std::abs(a[r * (N + 1) + k]) > std::abs(a[pivot * (N + 1) + k])) pivot = r;
        if (!(std::abs(a[pivot * (N + 1) + k]) > 1e-12 * (1.0 + std::abs(a[0])))) return {};
        for (std::size_t c = 0; c <= N; ++c) std::swap(a[k * (N + 1) + c], a[pivot * (N + 1) + c]);
        for (std::size_t r = 0; r < N; ++r) {
            if (r == k) continue;
            const double f = a[r * (N + 1) + k] / a[k * (N + 1) + k];
            for (std::size_t c = k; c <= N; ++c) a[r * (N + 1) + c] -= f * a[k * (N + 1) + c];
        }
    }
    std::vector<double> c(N);
    for (std::size_t k = 0; k < N; ++k) c[k] = a[k * (N + 1) + N] / a[k * (N + 1) + k];
    return c;
}

double polynomialAt(const std::vector<double>& c, int degree, double u, double v) {
    double z = 0.0;
    for (int j = 0; j <= degree; ++j)
        for (int i = 0; i <= degree; ++i)
            z += c[static_cast<std::size_t>(i + (degree + 1) * j)] * std::pow(u, i) * std::pow(v, j);
    return z;
}

} // namespace ff::ghosts
