#pragma once
// A tensor-product polynomial over (u, v), fitted by least squares: the smooth pupil rectangles of a
// two-dimensional shaped table (shaped_ghosts.cpp) are one per side.

#include <glm/vec3.hpp>

#include <vector>

namespace ff::ghosts {

/// Least squares over the points (u, v) -> z of a tensor product of polynomials of degree `degree`
/// (0..2) in u and in v: the coefficients c[i + (degree + 1) j] of u^i v^j; empty when singular.
std::vector<double> fitPolynomial(const std::vector<glm::dvec3>& points, int degree);

/// The polynomial of coefficients c (fitPolynomial) at (u, v).
double polynomialAt(const std::vector<double>& c, int degree, double u, double v);

} // namespace ff::ghosts
