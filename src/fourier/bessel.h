#pragma once
// The radial Fourier-Bessel variant (docs/fourier.md, last section). On a disc of radius R0 about
// the frame centre a radial profile is f(rho) ~ sum_j c_j J0(k_j rho), k_j = lambda_j / R0 (lambda_j
// the zeros of J0); Graf's addition theorem moves a ghost to (d, theta_d):
//
//     J0(k |r - d|) = sum_m eps_m J_m(k r) J_m(k d) cos(m (theta - theta_d)),   eps_0 = 1, eps_m = 2,
//
// so all ghosts aggregate into a_jm = sum_g alpha_g c_j eps_m J_m(k_j d_g) cos(m theta_g) and b_jm
// (with sin), and the flare is F(r, theta) = sum_m [cos(m theta) sum_j a_jm J_m(k_j r) + sin(m theta) ...].
// Evaluation: per ring of a polar grid, a radial contraction over j (Bessel values by Miller's
// backward recurrence) and one inverse real FFT over theta; pixels take bicubic (Catmull-Rom)
// samples of the polar grid.
//
// Scope: Gaussian ghosts, made isotropic with sigma = sqrt(sigma_x sigma_y) per channel (same area,
// so the same peak and flux). Values are point samples at pixel centres. Ghosts too small for the
// chosen J, or centred farther than 1.5 half-diagonals from the centre, are drawn directly.

#include "fourier/backend.h"
#include "fourier/render_result.h"

#include <vector>

namespace ff::fourier {

/// J_0(x) .. J_{count-1}(x) by Miller's backward recurrence, normalised with J0 + 2 sum J_2k = 1.
void besselSeries(double x, int count, double* out);

/// The first `count` positive zeros of J0.
std::vector<double> besselZeros(int count);

/// The ghosts through the Fourier-Bessel series. Throws ff::Error (Usage) for cos^2 ghosts.
FourierRender renderBessel(const std::vector<Ghost>& ghosts, int width, int height, const FourierSettings& settings);

} // namespace ff::fourier
