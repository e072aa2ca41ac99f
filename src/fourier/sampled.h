#pragma once
// Fourier coefficients of an arbitrary sampled profile — a traced ghost's image rather than a
// Gaussian or cos^2 fit — so that it can enter the same aggregation (docs/fourier.md, "Sampled
// profiles"). The samples are cell integrals (flux per cell, as a traced image holds them) on a
// regular grid of square cells; with cell centres x_i, y_j and spacing s,
//
//     A_nm = 1 / (Tx Ty) sum_ij P_ij cos(n wx x_i) cos(m wy y_j) / (sinc(n wx s / 2) sinc(m wy s / 2))
//
// and B, C, D with cos . sin, sin . cos, sin . sin: the midpoint sum of the continuous profile's
// coefficients once the cell's box (the sinc) is divided out. Exact up to aliasing, i.e. for profiles
// sampled finely enough that nothing above the grid's Nyquist frequency remains; terms must stay
// below it (n < Tx / s), which the functions check.

#include "fourier/aggregate.h"

#include <vector>

namespace ff::fourier {

struct SampledGhost {
    double x0 = 0.0, y0 = 0.0; ///< frame position of the first cell's top-left corner, pixels
    double step = 1.0;         ///< cell size, pixels
    int width = 0, height = 0; ///< cells
    std::vector<float> values; ///< R, G, B interleaved, rows of `width` cells; flux per cell
};

/// Throws ff::Error (Usage) when a ghost's values do not match its size, its step is not positive,
/// or the terms reach the cells' Nyquist frequency.
void checkSampled(const std::vector<SampledGhost>& ghosts, int n, int m, double periodX, double periodY);

/// Adds the sampled ghosts' coefficients to z (its n, m and periods), in float64.
void accumulateSampled(const std::vector<SampledGhost>& ghosts, Coefficients& z);

/// The same sum for one grid that spans the periods exactly (width x step = periodX, height x step =
/// periodY) with its cells' centres on multiples of the step, through one r2c FFT per channel
/// (float32, ~1e-6 of the largest coefficient): O(G log G) instead of O(N G). Throws ff::Error
/// (Usage) when the grid does not fit so or the terms pass its Nyquist frequency (2n > width,
/// 2m > height).
void accumulateSampledGrid(const SampledGhost& grid, Coefficients& z);

} // namespace ff::fourier
