#pragma once
// Accumulating the separable Fourier coefficients of many ghosts (docs/fourier.md, matrix form):
//
//     Z = [[A, B], [C, D]] = [Pc Ps]^T diag(alpha) [Qc Qs]   per colour channel,
//     Pc[k, n] = g_n^k cos(n wx x_k), Ps[k, n] = g_n^k sin(n wx x_k), Qc, Qs likewise on y.
//
// Precision: each ghost's coefficients and phases are computed in float64 and stored as float32;
// the products over ghosts are float32 GEMMs (OpenBLAS sgemm) over chunks of at most 4096 ghosts,
// and the chunks' partial sums are added in float64, so rounding does not grow with the number of
// ghosts (each GEMM on one OpenBLAS thread, chunks in parallel on TBB).
// Ghosts are summed by the plan's groups (Plan::groups: shape and kept terms): a group's result fills
// only the top-left block of A, B, C and D it needs, so large ghosts cost few multiply-adds; a group
// the plan put on a grid is spread and transformed instead (gridded.h), which costs each ghost its
// stencil rather than its terms.

#include "fourier/plan.h"

#include <array>
#include <vector>

namespace ff::fourier {

struct Coefficients {
    int n = 0, m = 0;
    double periodX = 0.0, periodY = 0.0;
    std::array<std::vector<double>, 3> z; ///< per channel, 2n x 2m row-major: [[A, B], [C, D]]

    /// All-zero coefficients of the plan's size and periods.
    static Coefficients zeros(const Plan& plan);

    double& at(int c, int row, int col) { return z[c][static_cast<std::size_t>(row) * 2 * m + col]; }
    double at(int c, int row, int col) const { return z[c][static_cast<std::size_t>(row) * 2 * m + col]; }
};

/// Sums the ghosts routed to Fourier by the plan.
Coefficients accumulate(const std::vector<Ghost>& ghosts, const Plan& plan, const FourierSettings& settings);

} // namespace ff::fourier
