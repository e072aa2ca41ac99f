// sampled_coefficients.comp + sum_coefficients.comp: the coefficients of sampled Gaussians against
// their closed form, and against the CPU's fourier::accumulateSampled on several ghosts of different
// cell sizes (more ghosts than one slice chunk would need, to exercise the ordered sum).

#include "fourier/sampled_gaussian_support.h"
#include "gpu/gl_context.h"
#include "gpu/gl_sampled.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "gl_test_support.h"

namespace ff::gpu {
namespace {

fourier::Coefficients zeros(int n, int m, double tx, double ty) {
    fourier::Coefficients z;
    z.n = n;
    z.m = m;
    z.periodX = tx;
    z.periodY = ty;
    for (auto& ch : z.z) ch.assign(static_cast<std::size_t>(4) * n * m, 0.0);
    return z;
}

TEST(GlSampled, SampledGaussianMatchesTheClosedForm) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    GlSampled gl(*context);
    const double rgb[3] = {1.0, 0.5, 0.25};
    for (double step : {1.0, 0.5}) {
        const double cx = 100.3, cy = 80.7, sx = 3.0, sy = 5.0;
        fourier::Coefficients z = zeros(32, 24, 256.0, 192.0);
        gl.accumulate({fourier::testing::sampledGaussian(cx, cy, sx, sy, step, rgb)}, z);
        const double a00 = 1.0 / (z.periodX * z.periodY);
        double worst = 0.0;
        for (int c = 0; c < 3; ++c)
            for (int n = 0; n < z.n; ++n)
                for (int m = 0; m < z.m; ++m) {
                    const double norm = rgb[c] / (2.0 * std::numbers::pi * sx * sy);
                    const auto [gc, gs] = fourier::testing::gaussianTerm(n, sx, cx, z.periodX);
                    const auto [hc, hs] = fourier::testing::gaussianTerm(m, sy, cy, z.periodY);
                    worst = std::max({worst, std::abs(z.at(c, n, m) - norm * gc * hc),
                                      std::abs(z.at(c, n, z.m + m) - norm * gc * hs),
                                      std::abs(z.at(c, z.n + n, m) - norm * gs * hc),
                                      std::abs(z.at(c, z.n + n, z.m + m) - norm * gs * hs)});
                }
        // float32 sums over the cells and float phases 2 pi fract(n u): 1e-5 of the mean term.
        char worstText[32];
        std::snprintf(worstText, sizeof worstText, "%.3g", worst / a00);
        RecordProperty(step == 1.0 ? "worst_of_a00_step1" : "worst_of_a00_step0.5", worstText);
        EXPECT_LT(worst, 1e-5 * a00) << "step " << step << ": worst " << worst / a00 << " of A00";
    }
}

TEST(GlSampled, MatchesTheCpuOnSeveralGhosts) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    GlSampled gl(*context);
    std::vector<fourier::SampledGhost> ghosts;
    for (int k = 0; k < 12; ++k) {
        const double rgb[3] = {1.0 + 0.1 * k, 0.5, 0.2 * k};
        ghosts.push_back(fourier::testing::sampledGaussian(20.0 + 13.7 * k, 15.0 + 7.3 * k, 1.5 + 0.2 * k,
                                                           2.0 + 0.1 * k, k % 3 ? 1.0 : 0.5, rgb));
    }
    fourier::Coefficients cpu = zeros(24, 16, 200.0, 128.0), gpu = cpu;
    cpu.at(1, 2, 3) = gpu.at(1, 2, 3) = 1e-4; // the sums add to what z holds
    fourier::accumulateSampled(ghosts, cpu);
    gl.accumulate(ghosts, gpu);
    EXPECT_LE(testing::coefficientDifference(gpu, cpu), 1e-5);
}

} // namespace
} // namespace ff::gpu
