#include "fourier/sampled.h"

#include "core/error.h"
#include "fourier/fftw_planner.h"
#include "fourier/gridded.h"

#include <cmath>
#include <numbers>
#include <string>

namespace ff::fourier {

namespace {

// cos and sin of n w (x0 + (i + 1/2) s) for i < count, phases reduced in float64.
void phases(int n, double w, double x0, double s, int count, std::vector<double>& c, std::vector<double>& si) {
    c.resize(static_cast<std::size_t>(count));
    si.resize(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) {
        const double p = std::fmod(n * w * (x0 + (i + 0.5) * s), 2.0 * std::numbers::pi);
        c[static_cast<std::size_t>(i)] = std::cos(p);
        si[static_cast<std::size_t>(i)] = std::sin(p);
    }
}

void checkOne(const SampledGhost& g, std::size_t k, int n, int m, double periodX, double periodY) {
    const std::string which = "sampled ghost " + std::to_string(k) + ": ";
    if (g.width <= 0 || g.height <= 0 || g.values.size() != static_cast<std::size_t>(g.width) * g.height * 3)
        throw Error(ErrorKind::Usage,
                    which + "expected " + std::to_string(g.width) + " x " + std::to_string(g.height) + " RGB cells");
    if (!(g.step > 0.0) || !std::isfinite(g.step) || !std::isfinite(g.x0) || !std::isfinite(g.y0))
        throw Error(ErrorKind::Usage, which + "the cell size and position must be finite, the size positive");
    // The box's sinc must stay away from its first zero at n w s / 2 = pi.
    if (n * g.step >= periodX || m * g.step >= periodY)
        throw Error(ErrorKind::Usage, which + "cells of " + std::to_string(g.step) + " px cannot carry " +
                                          std::to_string(n) + " x " + std::to_string(m) +
                                          " terms (Nyquist): sample finer or use fewer terms");
}

} // namespace

void checkSampled(const std::vector<SampledGhost>& ghosts, int n, int m, double periodX, double periodY) {
    for (std::size_t k = 0; k < ghosts.size(); ++k) checkOne(ghosts[k], k, n, m, periodX, periodY);
}

void accumulateSampled(const std::vector<SampledGhost>& ghosts, Coefficients& z) {
    checkSampled(ghosts, z.n, z.m, z.periodX, z.periodY);
    const double wx = 2.0 * std::numbers::pi / z.periodX, wy = 2.0 * std::numbers::pi / z.periodY;
    std::vector<double> cx, sx, cy, sy;
    for (const SampledGhost& g : ghosts) {
        const auto W = static_cast<std::size_t>(g.width);
        // Row sums R[c][n][j] = sum_i P_ij (cos, sin)(n wx x_i): O(N W H + N M H) instead of O(N M W H).
        std::vector<double> rc(3 * static_cast<std::size_t>(z.n) * g.height), rs(rc.size());
        for (int n = 0; n < z.n; ++n) {
            phases(n, wx, g.x0, g.step, g.width, cx, sx);
            for (int j = 0; j < g.height; ++j)
                for (int c = 0; c < 3; ++c) {
                    double a = 0.0, b = 0.0;
                    for (std::size_t i = 0; i < W; ++i) {
                        const double p =
                            g.values[(static_cast<std::size_t>(j) * W + i) * 3 + static_cast<std::size_t>(c)];
                        a += p * cx[i];
                        b += p * sx[i];
                    }
                    const std::size_t r = (static_cast<std::size_t>(c) * z.n + n) * g.height + j;
                    rc[r] = a;
                    rs[r] = b;
                }
        }
        for (int m = 0; m < z.m; ++m) {
            phases(m, wy, g.y0, g.step, g.height, cy, sy);
            const double boxY = sinc(0.5 * m * wy * g.step);
            for (int n = 0; n < z.n; ++n) {
                const double scale = 1.0 / (z.periodX * z.periodY * sinc(0.5 * n * wx * g.step) * boxY);
                for (int c = 0; c < 3; ++c) {
                    double a = 0.0, b = 0.0, cc = 0.0, d = 0.0;
                    const std::size_t r0 = (static_cast<std::size_t>(c) * z.n + n) * g.height;
                    for (int j = 0; j < g.height; ++j) {
                        const double pc = rc[r0 + j], ps = rs[r0 + j];
                        a += pc * cy[j];
                        b += pc * sy[j];
                        cc += ps * cy[j];
                        d += ps * sy[j];
                    }
                    z.at(c, n, m) += scale * a;
                    z.at(c, n, z.m + m) += scale * b;
                    z.at(c, z.n + n, m) += scale * cc;
                    z.at(c, z.n + n, z.m + m) += scale * d;
                }
            }
        }
    }
}

void accumulateSampledGrid(const SampledGhost& g, Coefficients& z) {
    checkOne(g, 0, z.n, z.m, z.periodX, z.periodY);
    const int gx = g.width, gy = g.height;
    const double h = g.step;
    if (std::abs(gx * h - z.periodX) > 1e-9 * z.periodX || std::abs(gy * h - z.periodY) > 1e-9 * z.periodY)
        throw Error(ErrorKind::Usage, "a sampled grid must span the periods exactly");
    if (2 * z.n > gx || 2 * z.m > gy)
        throw Error(ErrorKind::Usage, "a grid of " + std::to_string(gx) + " x " + std::to_string(gy) +
                                          " cells cannot carry " + std::to_string(z.n) + " x " + std::to_string(z.m) +
                                          " terms (Nyquist)");
    // Cell i's centre x0 + (i + 1/2) h = kx h: the sample at index (i + kx) mod gx of a grid from 0.
    const double kx = g.x0 / h + 0.5, ky = g.y0 / h + 0.5;
    if (std::abs(kx - std::round(kx)) > 1e-9 || std::abs(ky - std::round(ky)) > 1e-9)
        throw Error(ErrorKind::Usage, "a sampled grid's cell centres must lie on multiples of its step");
    const auto wrap = [](long long i, int size) { return static_cast<std::size_t>(((i % size) + size) % size); };
    const long long sx = std::llround(kx), sy = std::llround(ky);
    const std::size_t cells = static_cast<std::size_t>(gx) * gy;
    const auto in = fftwArray<float>(cells);
    const auto out = fftwArray<fftwf_complex>(static_cast<std::size_t>(gx / 2 + 1) * gy);
    if (!in || !out) throw Error(ErrorKind::Runtime, "out of memory for a sampled grid's transform");
    const fftwf_plan plan = gridTransform(gx, gy);
    const double wx = 2.0 * std::numbers::pi / z.periodX, wy = 2.0 * std::numbers::pi / z.periodY;
    for (int c = 0; c < 3; ++c) {
        for (int j = 0; j < gy; ++j) {
            float* row = in.get() + wrap(j + sy, gy) * gx;
            const float* src = &g.values[static_cast<std::size_t>(j) * gx * 3 + static_cast<std::size_t>(c)];
            for (int i = 0; i < gx; ++i) row[wrap(i + sx, gx)] = src[static_cast<std::size_t>(i) * 3];
        }
        fftwf_execute_dft_r2c(plan, in.get(), out.get());
        const std::vector<double> t = coefficientsOfTransform(out.get(), gx, gy, z.n, z.m);
        // Cell integrals over h^2 are the density's samples, each term's box (sinc) divided out.
        for (int n = 0; n < 2 * z.n; ++n) {
            const double boxX = sinc(0.5 * (n % z.n) * wx * h) * h * h;
            for (int m = 0; m < 2 * z.m; ++m)
                z.at(c, n, m) += t[static_cast<std::size_t>(n) * 2 * z.m + m] / (boxX * sinc(0.5 * (m % z.m) * wy * h));
        }
    }
}

} // namespace ff::fourier
