#pragma once
// The per-channel block every ghost struct of the shaders ends with (std430: three vec4 — widths along
// x and y, and the peak, per channel; w unused), filled from a fourier::Ghost.

#include "fourier/ghost.h"

#include <array>
#include <cmath>

namespace ff::gpu {

struct GpuChannels {
    std::array<float, 4> widthX{}, widthY{}, peak{};
};
static_assert(sizeof(GpuChannels) == 48);

inline GpuChannels gpuChannels(const fourier::Ghost& g) {
    GpuChannels ch;
    for (int c = 0; c < 3; ++c) {
        ch.widthX[c] = static_cast<float>(g.widthX[c]);
        ch.widthY[c] = static_cast<float>(g.widthY[c]);
        ch.peak[c] = static_cast<float>(g.peak(c));
    }
    return ch;
}

/// x / period reduced to [0, 1) in double: the shaders' phases 2 pi fract(n u) then stay exact to
/// float rounding.
inline float periodFraction(double x, double period) {
    const double f = x / period - std::floor(x / period);
    return static_cast<float>(f >= 1.0 ? 0.0 : f);
}

/// The shaders' shape code: 0 Gaussian, 1 cos^2.
inline float gpuShape(const fourier::Ghost& g) {
    return g.shape == fourier::Shape::Gaussian ? 0.0f : 1.0f;
}

} // namespace ff::gpu
