#include "fourier/sampled.h"

#include "core/error.h"

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

} // namespace

void checkSampled(const std::vector<SampledGhost>& ghosts, int n, int m, double periodX, double periodY) {
    for (std::size_t k = 0; k < ghosts.size(); ++k) {
        const SampledGhost& g = ghosts[k];
        const std::string which = "sampled ghost " + std::to_string(k) + ": ";
        if (g.width <= 0 || g.height <= 0 || g.values.size() != static_cast<std::size_t>(g.width) * g.height * 3)
            throw Error(ErrorKind::Usage, which + "expected " + std::to_string(g.width) + " x " +
                                              std::to_string(g.height) + " RGB cells");
        if (!(g.step > 0.0) || !std::isfinite(g.step) || !std::isfinite(g.x0) || !std::isfinite(g.y0))
            throw Error(ErrorKind::Usage, which + "the cell size and position must be finite, the size positive");
        // The box's sinc must stay away from its first zero at n w s / 2 = pi.
        if (n * g.step >= periodX || m * g.step >= periodY)
            throw Error(ErrorKind::Usage, which + "cells of " + std::to_string(g.step) + " px cannot carry " +
                                              std::to_string(n) + " x " + std::to_string(m) +
                                              " terms (Nyquist): sample finer or use fewer terms");
    }
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

} // namespace ff::fourier
