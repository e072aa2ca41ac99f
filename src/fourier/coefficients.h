#pragma once
// Closed-form cosine coefficients of one-dimensional ghost profiles on a period T
// (reference: docs/fourier.md). A profile p(u) is even with p(0) = 1, truncated to one period around
// its centre and repeated; its coefficients carry the 1/T:
//
//     p_n = (1/T) Int_{-T/2}^{T/2} p(u) cos(n w u) du,   w = 2 pi / T,
//     p(u) = sum_{n >= 0} kappa_n p_n cos(n w u),        kappa_0 = 1, kappa_n = 2.

namespace ff::fourier {

enum class Shape { Gaussian, Cos2 };
const char* toString(Shape s);

/// How the Gaussian's coefficients are computed.
enum class GaussianForm {
    Periodised, ///< (sigma sqrt(2 pi) / T) exp(-b^2): the untruncated Gaussian's transform (default)
    Exact,      ///< the profile truncated to one period: Re[exp(-b^2) erf(a + i b)], complex erf
    ErfAS7126,  ///< exp(-b^2) erf(a) with Abramowitz & Stegun 7.1.26 for erf (|error| <= 1.5e-7)
};
const char* toString(GaussianForm f);

/// Coefficient n of exp(-u^2 / (2 sigma^2)) on period T.
double gaussianCoefficient(int n, double sigma, double period, GaussianForm form = GaussianForm::Periodised);

/// Coefficient n of cos^2(pi u / (2 w)) on |u| < w (0 elsewhere), w <= T / 2, on period T, through
/// the Hann-window form (w/T) [S(t) + S(t - pi)/2 + S(t + pi)/2], S(u) = sin(u)/u, t = n w_T w:
/// no special case at the removable singularities.
double cos2Coefficient(int n, double halfWidth, double period);

double coefficient(Shape s, int n, double width, double period, GaussianForm form = GaussianForm::Periodised);

/// Integral of the unit-peak profile over the line: sigma sqrt(2 pi) (Gaussian), w (cos^2).
double profileIntegral(Shape s, double width);

/// erf through Abramowitz & Stegun 7.1.26 (odd extension to x < 0).
double erfAS7126(double x);

/// sin(u) / u, 1 at 0: the transform of a box (a pixel or a sample cell) and of the cos^2 bump's parts.
double sinc(double u);

/// Re[exp(-y^2) erf(x + i y)] for x > 0, by the series of Abramowitz & Stegun 7.1.29 with the
/// exp(-y^2) folded into every term so that nothing overflows for large y.
double scaledRealErf(double x, double y);

/// x* of a shape for a relative L2 truncation error `error` of a single ghost (both axes together):
/// the spectral variable 2 pi n width / T beyond which each axis keeps less than error^2 / 2 of the
/// profile's squared norm (Gaussian: erfc(x*) = error^2 / 2; cos^2: its tail, tabulated).
double spectralCutoff(Shape s, double error);

/// The number of terms n < N on one axis that keeps that error: ceil(x* T / (2 pi width)) + 1 (the
/// +1 bounds the discrete tail by the integral), capped at 2^20.
int termsForCutoff(double cutoff, double width, double period);
int termsForError(Shape s, double width, double period, double error);

} // namespace ff::fourier
