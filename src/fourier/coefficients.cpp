#include "fourier/coefficients.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace ff::fourier {

const char* toString(Shape s) {
    return s == Shape::Gaussian ? "gaussian" : "cos2";
}

const char* toString(GaussianForm f) {
    switch (f) {
    case GaussianForm::Periodised:
        return "periodised";
    case GaussianForm::Exact:
        return "exact";
    case GaussianForm::ErfAS7126:
        return "as7126";
    }
    return "?";
}

double erfAS7126(double x) {
    const double s = x < 0.0 ? -1.0 : 1.0;
    x = std::abs(x);
    const double t = 1.0 / (1.0 + 0.3275911 * x);
    const double poly =
        t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
    return s * (1.0 - poly * std::exp(-x * x));
}

double scaledRealErf(double x, double y) {
    // A&S 7.1.29, real part, times exp(-y^2):
    //   exp(-y^2) erf(x) + exp(-x^2 - y^2) (1 - cos 2xy) / (2 pi x)
    //   + (2/pi) exp(-x^2) sum_n exp(-n^2/4 - y^2) / (n^2 + 4x^2) [2x - 2x cosh(ny) cos(2xy) + n sinh(ny) sin(2xy)]
    // with exp(-n^2/4 - y^2) cosh(ny) = (e+ + e-)/2 and ... sinh(ny) = (e- - e+)/2... written out below,
    // e- = exp(-(y - n/2)^2), e+ = exp(-(y + n/2)^2): every factor stays below 1.
    const double pi = std::numbers::pi;
    const double c = std::cos(2.0 * x * y), s = std::sin(2.0 * x * y);
    double sum = 0.0;
    const int last = static_cast<int>(std::ceil(2.0 * std::abs(y))) + 14;
    for (int n = 1; n <= last; ++n) {
        const double em = std::exp(-(y - 0.5 * n) * (y - 0.5 * n)), ep = std::exp(-(y + 0.5 * n) * (y + 0.5 * n));
        const double flat = std::exp(-0.25 * n * n - y * y);
        const double coshT = 0.5 * (em + ep), sinhT = 0.5 * (em - ep);
        sum += (2.0 * x * flat - 2.0 * x * coshT * c + n * sinhT * s) / (n * n + 4.0 * x * x);
    }
    const double ex = std::exp(-x * x);
    return std::exp(-y * y) * std::erf(x) + ex * std::exp(-y * y) * (1.0 - c) / (2.0 * pi * x) + (2.0 / pi) * ex * sum;
}

double gaussianCoefficient(int n, double sigma, double T, GaussianForm form) {
    const double scale = sigma * std::sqrt(2.0 * std::numbers::pi) / T;
    const double b = n * (2.0 * std::numbers::pi / T) * sigma / std::numbers::sqrt2;
    const double a = T / (2.0 * std::numbers::sqrt2 * sigma);
    switch (form) {
    case GaussianForm::Periodised:
        return scale * std::exp(-b * b);
    case GaussianForm::Exact:
        return scale * scaledRealErf(a, b);
    case GaussianForm::ErfAS7126:
        return scale * std::exp(-b * b) * erfAS7126(a);
    }
    return 0.0;
}

double sinc(double u) {
    return u == 0.0 ? 1.0 : std::sin(u) / u;
}

namespace {

// The cos^2 coefficient's shape: T h_n / w as a function of theta = n w_T w.
double hann(double t) {
    return sinc(t) + 0.5 * sinc(t - std::numbers::pi) + 0.5 * sinc(t + std::numbers::pi);
}

// (4 / (3 pi)) Int_x^inf hann(t)^2 dt: the fraction of a cos^2 profile's squared norm beyond
// theta = x, from a table of the running integral (trapezoids of 1e-3) and the asymptotic tail
// hann^2 ~ pi^4 sin^2 t / t^6 beyond it.
double cos2SpectralTail(double x) {
    constexpr double step = 1e-3, end = 400.0;
    static const std::vector<double> cumulative = [] {
        const auto n = static_cast<std::size_t>(end / step);
        std::vector<double> c(n + 1, 0.0);
        for (std::size_t i = 1; i <= n; ++i) {
            const double a = hann(double(i - 1) * step), b = hann(double(i) * step);
            c[i] = c[i - 1] + 0.5 * step * (a * a + b * b);
        }
        return c;
    }();
    const double pi = std::numbers::pi;
    const double beyond = std::pow(pi, 4) / (10.0 * std::pow(end, 5));
    if (x >= end) return 4.0 / (3.0 * pi) * std::pow(pi, 4) / (10.0 * std::pow(x, 5));
    const double pos = std::max(0.0, x) / step;
    const auto i = static_cast<std::size_t>(pos);
    const double f = pos - double(i);
    const double atX = cumulative[i] + f * (cumulative[std::min(i + 1, cumulative.size() - 1)] - cumulative[i]);
    return 4.0 / (3.0 * pi) * (cumulative.back() - atX + beyond);
}

// Smallest x with tail(x) <= target, tail decreasing (bisection).
template <typename F>
double solveTail(F tail, double target, double hi) {
    double lo = 0.0;
    while (tail(hi) > target && hi < 1e6) hi *= 2.0;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (tail(mid) > target ? lo : hi) = mid;
    }
    return hi;
}

} // namespace

double cos2Coefficient(int n, double w, double T) {
    return (w / T) * hann(n * (2.0 * std::numbers::pi / T) * w);
}

double coefficient(Shape s, int n, double width, double period, GaussianForm form) {
    return s == Shape::Gaussian ? gaussianCoefficient(n, width, period, form) : cos2Coefficient(n, width, period);
}

double profileIntegral(Shape s, double width) {
    return s == Shape::Gaussian ? width * std::sqrt(2.0 * std::numbers::pi) : width;
}

double spectralCutoff(Shape s, double error) {
    if (!(error > 0.0)) return std::numeric_limits<double>::infinity();
    // Both axes share the squared error: each keeps its spectral tail below error^2 / 2.
    const double target = 0.5 * error * error;
    return s == Shape::Gaussian ? solveTail([](double t) { return std::erfc(t); }, target, 8.0)
                                : solveTail(cos2SpectralTail, target, 64.0);
}

int termsForCutoff(double cutoff, double width, double period) {
    constexpr int kMax = 1 << 20;
    if (!(width > 0.0)) return kMax;
    const double n = std::ceil(cutoff * period / (2.0 * std::numbers::pi * width)) + 1.0;
    return n >= kMax ? kMax : static_cast<int>(n);
}

int termsForError(Shape s, double width, double period, double error) {
    return termsForCutoff(spectralCutoff(s, error), width, period);
}

} // namespace ff::fourier
