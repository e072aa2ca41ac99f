// direct_axes.comp + direct_draw.comp against fourier::drawDirect: small ghosts of both profiles,
// per-axis and per-channel widths, some hanging over the frame's edges, more than one chunk of 256,
// drawn on top of an image that is not zero (the shaders add); in one batch and in many.

#include "fourier/direct.h"
#include "gpu/gl_context.h"
#include "gpu/gl_direct.h"

#include <gtest/gtest.h>

#include "gl_test_support.h"

namespace ff::gpu {
namespace {

TEST(GlDirect, MatchesTheCpuDrawing) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    // The default batch holds every ghost's axis integrals; 200 integrals per batch makes dozens.
    for (std::size_t batch : {GlDirect::kDefaultBatch, std::size_t(200)}) {
        for (auto shape : {fourier::Shape::Gaussian, fourier::Shape::Cos2}) {
            SCOPED_TRACE("batch " + std::to_string(batch));
            GlDirect gl(*context, batch);
            const int W = 150, H = 90; // not multiples of the 16-pixel tile
            const auto ghosts = testing::randomGhosts(300, shape, W, H, 11, 0.3, 6.0);
            std::vector<std::size_t> which;
            for (std::size_t k = 0; k < ghosts.size(); k += (k % 7 == 3 ? 2 : 1))
                which.push_back(k); // a subset, in order
            fourier::FlareImage cpu(W, H);
            for (int c = 0; c < 3; ++c)
                for (std::size_t p = 0; p < cpu.pixels(); ++p) cpu.channel[c][p] = 0.01f * float((p * 7 + c) % 13);
            fourier::FlareImage gpu = cpu;
            fourier::drawDirect(ghosts, which, cpu);
            gl.draw(ghosts, which, gpu);
            const auto d = testing::difference(gpu, cpu);
            // float32 sums and the A&S 7.1.26 erfc (absolute error 1.5e-7 per pixel integral).
            EXPECT_LE(d.relativeL2, 1e-5) << fourier::toString(shape);
            EXPECT_LE(d.worst, 1e-5 * d.peak) << fourier::toString(shape);
        }
    }
}

TEST(GlDirect, GhostsOutsideTheFrameDrawNothing) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    GlDirect gl(*context);
    fourier::Ghost far;
    far.x = -50.0;
    far.y = 10.0;
    far.widthX = far.widthY = {2.0, 2.0, 2.0};
    far.flux = {1.0, 1.0, 1.0};
    fourier::FlareImage image(20, 20);
    gl.draw({far}, {0}, image);
    for (int c = 0; c < 3; ++c)
        for (float v : image.channel[c]) EXPECT_EQ(v, 0.0f);
}

} // namespace
} // namespace ff::gpu
