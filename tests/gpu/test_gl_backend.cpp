// The GL backend end to end (fourier::renderFourier with settings.backend): accumulation,
// evaluation and direct drawing on the GPU against the CPU renderer, on a hybrid plan with a coarse
// level, for both profiles; then its composite against image::composite.

#include "fourier/render.h"
#include "gpu/gl_backend.h"
#include "image/composite.h"

#include <gtest/gtest.h>

#include <cstring>

#include "gl_test_support.h"

namespace ff::gpu {
namespace {

TEST(GlBackend, RendersWhatTheCpuRenders) {
    std::string why;
    auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    auto gl = std::make_shared<GlBackend>(std::move(context));
    const int W = 176, H = 100;
    for (auto shape : {fourier::Shape::Gaussian, fourier::Shape::Cos2}) {
        auto ghosts = testing::randomGhosts(150, shape, W, H, 21, 0.5, 30.0);
        // Forty ghosts far wider than the frame: the coarse level.
        for (int k = 0; k < 40; ++k) {
            ghosts[k].widthX = {300.0 + 5 * k, 310.0, 320.0};
            ghosts[k].widthY = {200.0, 210.0, 220.0 + 3 * k};
        }
        fourier::FourierSettings s;
        s.fixedN = 40; // the budget alone draws everything directly at this frame size
        const fourier::FourierRender cpu = fourier::renderFourier(ghosts, W, H, s);
        s.backend = gl;
        const fourier::FourierRender gpu = fourier::renderFourier(ghosts, W, H, s);
        std::printf("%s: %s; GL vs CPU relative L2 %.2e, largest difference %.2e of the peak\n",
                    fourier::toString(shape), cpu.describe().c_str(),
                    testing::difference(gpu.image, cpu.image).relativeL2,
                    testing::difference(gpu.image, cpu.image).worst / testing::difference(gpu.image, cpu.image).peak);
        ASSERT_GT(cpu.plan.fourier, 0u);
        ASSERT_GT(cpu.plan.direct, 0u) << "the plan should split the ghosts (hybrid)";
        ASSERT_TRUE(cpu.coarse.has_value());
        // (cos^2's slowly decaying spectrum makes direct drawing the cheaper choice on the coarse level.)
        if (shape == fourier::Shape::Gaussian) {
            ASSERT_GT(cpu.coarse->fourier, 0u);
        }
        EXPECT_EQ(cpu.describe(), gpu.describe());
        const auto d = testing::difference(gpu.image, cpu.image);
        // The CPU trims each ghost to its own terms (trimFraction of the budget) where the GPU sums
        // all N x M: the two differ by at most that share of the 1e-3 budget, far less in practice.
        EXPECT_LE(d.relativeL2, 2.5e-4) << fourier::toString(shape);
        EXPECT_LE(d.worst, 2.5e-4 * d.peak) << fourier::toString(shape);
        // Composited on the GPU from the frame it holds: the CPU's composite of the read-back flare.
        std::vector<float> plate(static_cast<std::size_t>(3) * W * H);
        for (std::size_t i = 0; i < plate.size(); ++i) plate[i] = 0.25f * float(i % 11);
        const std::vector<float> flare = gpu.image.interleaved(), a = gl->composite(plate),
                                 b = image::composite(plate, flare);
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);
    }
}

TEST(GlBackend, AnUntrimmedCpuRenderAgreesToFloatPrecision) {
    std::string why;
    auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    auto gl = std::make_shared<GlBackend>(std::move(context));
    const int W = 128, H = 80;
    const auto ghosts = testing::randomGhosts(80, fourier::Shape::Gaussian, W, H, 4, 0.5, 12.0);
    fourier::FourierSettings s;
    s.trimFraction = 0.0; // every ghost over all N x M terms, as the GPU sums them
    const fourier::FourierRender cpu = fourier::renderFourier(ghosts, W, H, s);
    s.backend = gl;
    const fourier::FourierRender gpu = fourier::renderFourier(ghosts, W, H, s);
    const auto d = testing::difference(gpu.image, cpu.image);
    EXPECT_LE(d.relativeL2, 1e-5);
    EXPECT_LE(d.worst, 1e-5 * d.peak);
}

} // namespace
} // namespace ff::gpu
