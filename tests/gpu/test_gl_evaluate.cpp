// The GL evaluation against the CPU's matrix form on the same coefficients (random ghosts, both
// profiles, per-axis widths, a hybrid plan). Runs on whatever EGL offers — llvmpipe in CI — and skips,
// saying why, where no context can be made.

#include "core/error.h"
#include "fourier/render.h"
#include "gpu/gl_accumulator.h"
#include "gpu/gl_context.h"
#include "gpu/gl_evaluator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gl_test_support.h"

namespace ff::gpu {
namespace {

using testing::randomGhosts;

TEST(GlEvaluate, MatchesTheCpuMatrixForm) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    std::printf("renderer: %s (work groups up to %d invocations)\n", context->renderer().c_str(),
                context->maxWorkGroupInvocations());
    GlEvaluator gl(*context);
    const int W = 160, H = 96;
    for (auto shape : {fourier::Shape::Gaussian, fourier::Shape::Cos2}) {
        const auto ghosts = randomGhosts(60, shape, W, H, 3);
        fourier::FourierSettings s;
        s.error = 1e-3;
        s.fixedN = 48; // the budget alone would draw everything directly at this size
        const fourier::Plan plan = fourier::choosePlan(ghosts, W, H, s);
        ASSERT_GT(plan.n, 0);
        const fourier::Coefficients z = fourier::accumulate(ghosts, plan, s);
        fourier::FlareImage cpu(W, H), gpu(W, H);
        fourier::evaluate(z, fourier::Evaluation::Matrix, cpu);
        gl.evaluate(z, gpu);
        const auto d = testing::difference(gpu, cpu);
        // Both are float32 sums of 2M and 2N products in different orders: a few ulps per term.
        EXPECT_LE(d.relativeL2, 1e-5) << fourier::toString(shape) << ", N " << plan.n;
        EXPECT_LE(d.worst, 1e-5 * d.peak) << fourier::toString(shape);
    }
}

TEST(GlEvaluate, EmptyCoefficientsGiveABlackImage) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    GlEvaluator gl(*context);
    fourier::Coefficients z; // n = m = 0
    fourier::FlareImage image(8, 8);
    image.channel[0][3] = 5.0f;
    gl.evaluate(z, image);
    for (int c = 0; c < 3; ++c)
        for (float v : image.channel[c]) EXPECT_EQ(v, 0.0f);
}

} // namespace
} // namespace ff::gpu

namespace ff::gpu {
namespace {

// The accumulation shader against the CPU's GEMM accumulation (untrimmed, the same terms), through
// the coefficients and through the evaluated image.
TEST(GlAccumulate, MatchesTheCpuAccumulation) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    GlAccumulator gl(*context);
    const int W = 160, H = 96;
    for (auto shape : {fourier::Shape::Gaussian, fourier::Shape::Cos2}) {
        const auto ghosts = randomGhosts(60, shape, W, H, 5);
        fourier::FourierSettings s;
        s.fixedN = 48;
        s.trimFraction = 0.0;
        const fourier::Plan plan = fourier::choosePlan(ghosts, W, H, s);
        ASSERT_GT(plan.fourier, 0u);
        const fourier::Coefficients cpu = fourier::accumulate(ghosts, plan, s), gpu = gl.accumulate(ghosts, plan, s);
        // float32 profiles and phases (the phase argument reduced on the host): 1e-5 of the coefficients' norm.
        EXPECT_LE(testing::coefficientDifference(gpu, cpu), 1e-5) << fourier::toString(shape);
        fourier::FlareImage a(W, H), b(W, H);
        fourier::evaluate(cpu, fourier::Evaluation::Matrix, a);
        fourier::evaluate(gpu, fourier::Evaluation::Matrix, b);
        EXPECT_LE(testing::difference(b, a).relativeL2, 1e-5) << fourier::toString(shape);
    }
}

} // namespace
} // namespace ff::gpu

namespace ff::gpu {
namespace {

// A GL error (reading past a buffer's end) becomes an ff::Error naming the call, not a silent zero.
TEST(GlObjects, ErrorsAreReported) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    Buffer b;
    b.zeros(16);
    std::vector<float> out(64);
    try {
        b.download(out.data(), out.size() * sizeof(float));
        ADD_FAILURE() << "no error reported";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("a buffer download"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(checkGl("nothing")); // the error was consumed
}

} // namespace
} // namespace ff::gpu
