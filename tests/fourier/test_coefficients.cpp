// The closed-form coefficients against numerical quadrature written here, and the term rule against
// the truncation error it promises (Parseval on the coefficients, computed here from the definition).

#include "fourier/coefficients.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

namespace ff::fourier {
namespace {

// (1/T) Int_{-T/2}^{T/2} p(u) cos(n w u) du by composite Simpson on 20000 intervals (split at the
// cos^2 support so the kink sits on a node).
double quadrature(const std::function<double(double)>& p, int n, double T, double kink = 0.0) {
    const double w = 2.0 * std::numbers::pi / T;
    auto simpson = [&](double a, double b) {
        const int steps = 20000;
        const double h = (b - a) / steps;
        double s = 0.0;
        for (int i = 0; i <= steps; ++i) {
            const double u = a + i * h;
            s += (i == 0 || i == steps ? 1.0 : (i % 2 ? 4.0 : 2.0)) * p(u) * std::cos(n * w * u);
        }
        return s * h / 3.0;
    };
    if (kink > 0.0) return simpson(-kink, kink) / T; // p vanishes outside the kink
    return simpson(-0.5 * T, 0.5 * T) / T;
}

TEST(FourierCoefficients, ExactGaussianMatchesQuadratureOfTheTruncatedProfile) {
    const double T = 100.0;
    for (double sigma : {5.0, 20.0, 35.0}) { // up to sigma / T = 0.35: truncation matters
        auto p = [sigma](double u) { return std::exp(-u * u / (2.0 * sigma * sigma)); };
        const double g0 = quadrature(p, 0, T);
        for (int n : {0, 1, 2, 3, 5, 8, 13, 21}) {
            SCOPED_TRACE("sigma " + std::to_string(sigma) + " n " + std::to_string(n));
            EXPECT_NEAR(gaussianCoefficient(n, sigma, T, GaussianForm::Exact), quadrature(p, n, T), 1e-11 * g0);
        }
    }
}

TEST(FourierCoefficients, PeriodisedAndAS7126GaussiansAreWithinTheirStatedAccuracy) {
    const double T = 100.0;
    for (double sigma : {2.0, 5.0, 10.0}) { // sigma / T <= 0.1: the padding's guarantee
        auto p = [sigma](double u) { return std::exp(-u * u / (2.0 * sigma * sigma)); };
        const double g0 = quadrature(p, 0, T);
        for (int n = 0; n < 40; n += 3) {
            const double q = quadrature(p, n, T);
            EXPECT_NEAR(gaussianCoefficient(n, sigma, T, GaussianForm::Periodised), q, 1e-6 * g0);
            EXPECT_NEAR(gaussianCoefficient(n, sigma, T, GaussianForm::ErfAS7126), q, 1e-6 * g0);
        }
    }
    for (double x : {-2.0, -0.5, 0.0, 0.1, 0.7, 1.5, 3.0}) EXPECT_NEAR(erfAS7126(x), std::erf(x), 1.5e-7);
}

TEST(FourierCoefficients, Cos2MatchesQuadratureIncludingTheRemovableSingularities) {
    const double T = 64.0;
    // w = 8: theta = n w_T w = pi at n = T / (2w) = 4; w = 8 (1 - 1e-12) sits next to it.
    for (double w : {8.0, 8.0 * (1.0 - 1e-12), 13.7, 32.0}) {
        auto p = [w](double u) {
            const double c = std::cos(0.5 * std::numbers::pi * u / w);
            return std::abs(u) < w ? c * c : 0.0;
        };
        for (int n : {0, 1, 2, 3, 4, 5, 8, 17, 31}) {
            SCOPED_TRACE("w " + std::to_string(w) + " n " + std::to_string(n));
            EXPECT_NEAR(cos2Coefficient(n, w, T), quadrature(p, n, T, w), 1e-12);
        }
    }
    EXPECT_DOUBLE_EQ(cos2Coefficient(0, 8.0, 64.0), 8.0 / 64.0);
    EXPECT_NEAR(cos2Coefficient(4, 8.0, 64.0), 8.0 / (2.0 * 64.0), 1e-15); // theta = pi: w / 2T
}

// Relative L2 error of truncating a centred separable ghost to n < N, m < N, by Parseval on
// coefficients of the untruncated profiles summed far out.
double truncationError(const std::function<double(int)>& coef, int N) {
    double kept = 0.0, all = 0.0;
    for (int n = 0; n < 20000; ++n) {
        const double c = coef(n);
        const double e = (n == 0 ? 1.0 : 2.0) * c * c;
        all += e;
        if (n < N) kept += e;
    }
    const double f = kept / all;
    return std::sqrt(std::max(0.0, 1.0 - f * f));
}

TEST(FourierCoefficients, TermRuleKeepsASingleGhostWithinTheBudget) {
    const double T = 2000.0;
    for (double budget : {1e-2, 1e-3, 1e-4}) {
        for (double size : {5.0, 12.0, 40.0, 150.0}) {
            SCOPED_TRACE("budget " + std::to_string(budget) + " size " + std::to_string(size));
            const int nG = termsForError(Shape::Gaussian, size, T, budget);
            const auto gauss = [&](int n) {
                const double b = n * (2.0 * std::numbers::pi / T) * size / std::numbers::sqrt2;
                return std::exp(-b * b);
            };
            EXPECT_LE(truncationError(gauss, nG), budget);
            // And the rule is not wasteful: a third fewer terms breaks the budget.
            EXPECT_GT(truncationError(gauss, nG * 2 / 3), budget);
            const int nC = termsForError(Shape::Cos2, size, T, budget);
            const auto hann = [&](int n) { return cos2Coefficient(n, size, T); };
            EXPECT_LE(truncationError(hann, nC), budget);
            EXPECT_GT(truncationError(hann, nC * 2 / 3), budget);
        }
    }
}

TEST(FourierCoefficients, ScaledRealErfStaysFiniteForLargeImaginaryParts) {
    for (double y : {10.0, 50.0, 200.0}) {
        const double v = scaledRealErf(3.0, y);
        EXPECT_TRUE(std::isfinite(v));
        EXPECT_LT(std::abs(v), 1e-3);
    }
}

} // namespace
} // namespace ff::fourier
