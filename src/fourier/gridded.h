#pragma once
// Accumulation on a sampling grid: the coefficients of a sum of ghosts as one FFT of the sum sampled
// over the period (docs/fourier.md, "Gridded accumulation"). This is a type-1 non-uniform FFT whose
// spreading kernels are the ghosts' own profiles, so nothing is deconvolved:
//
//     s[j][i] = sum_k alpha_k p_k(i hx - x_k) q_k(j hy - y_k)     (periodic, hx = Tx / Gx, hy = Ty / Gy)
//     A_nm = (1 / Gx Gy) sum_ij s[j][i] cos(2 pi n i / Gx) cos(2 pi m j / Gy),   B, C, D likewise,
//
// which equals the closed-form coefficients of docs/fourier.md up to aliasing: term n also receives
// the profile's transform at G - n, G + n, ... The grid is sized so that the nearest alias, G - n with
// n below the group's terms, lies beyond a multiple of the profile's spectral cut-off (gridSamples).
// Each ghost costs its stencil (the samples within its extent: about 2 x 5 sigma / h per axis, the
// same for every width because h follows the width), not its N x M terms.
//
// Precision: profiles in float64, the grid and the FFT in float32 (FFTW), the result in float64;
// relative rounding of the transform ~1e-6 of the largest coefficient. Internal to ff_fourier.

#include "fourier/plan.h"

#include <array>
#include <fftw3.h>
#include <vector>

namespace ff::fourier {

/// Ghosts summed per task (one GEMM or one grid): accumulate() splits larger groups into chunks of
/// this many, run in parallel and added in order.
constexpr std::size_t kAccumulationChunk = 4096;

/// Samples per period on one axis for a group keeping `terms` terms whose narrowest profile is
/// `narrowest` wide: at least 2 terms + 1, and enough that the nearest alias lies beyond the
/// alias margin times the shape's spectral cut-off at `error`. FFT-friendly.
int gridSamples(Shape shape, int terms, double narrowest, double period, double error);

/// Samples one ghost's profile covers on one axis at spacing h (its stencil).
int stencilSamples(Shape shape, double width, double spacing);

/// Per channel, the 2n x 2m block [[A, B], [C, D]] (row-major) of ghosts
/// group.members[first, first + count), on the group's grid (one pass over the ghosts, three grids).
std::array<std::vector<double>, 3> accumulateGridded(const std::vector<Ghost>& ghosts, const AccumulationGroup& group,
                                                     std::size_t first, std::size_t count, double periodX,
                                                     double periodY);

/// The r2c plan of a gy x gx float grid (rows of gx), made once per size and kept; thread-safe.
fftwf_plan gridTransform(int gx, int gy);

/// The 2nb x 2mb block [[A, B], [C, D]] (row-major), over Gx Gy, from the r2c transform `f` of a
/// gy x gx grid whose sample (i, j) lies at (i hx, j hy): the series of the grid's samples.
std::vector<double> coefficientsOfTransform(const fftwf_complex* f, int gx, int gy, int nb, int mb);

} // namespace ff::fourier
