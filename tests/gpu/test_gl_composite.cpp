// composite.comp against image::composite, bit for bit: ordinary values, NaN, infinities, -0,
// subnormals and values that overflow, with the flare zero in some pixels and not in others.

#include "core/error.h"
#include "gpu/gl_composite.h"
#include "gpu/gl_context.h"
#include "image/composite.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <random>

namespace ff::gpu {
namespace {

TEST(GlComposite, IsBitIdenticalToTheCpuComposite) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    GlCompositor gl(*context);
    const int W = 37, H = 21;
    const std::size_t n = static_cast<std::size_t>(3) * W * H;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-2.0f, 50.0f);
    const float special[] = {std::numeric_limits<float>::quiet_NaN(),
                             std::numeric_limits<float>::infinity(),
                             -std::numeric_limits<float>::infinity(),
                             -0.0f,
                             1e-40f,
                             -3e-39f,
                             3.4e38f,
                             65504.0f};
    std::vector<float> plate(n), flare(n);
    for (std::size_t i = 0; i < n; ++i) {
        plate[i] = i % 5 == 0 ? special[(i / 5) % std::size(special)] : u(rng);
        // Zero flare on every third value, else a small or an ordinary one (3.4e38 + 1e38 overflows).
        flare[i] = i % 3 == 0 ? 0.0f : (i % 2 ? 1e-3f * (1.0f + u(rng)) : (i % 7 == 0 ? 1e38f : u(rng)));
    }
    std::vector<float> planes(n);
    for (std::size_t p = 0; p < n / 3; ++p)
        for (std::size_t c = 0; c < 3; ++c) planes[c * (n / 3) + p] = flare[p * 3 + c];
    Buffer flareBuffer;
    flareBuffer.upload(planes.data(), planes.size() * sizeof(float));
    const std::vector<float> gpu = gl.composite(plate, W, H, flareBuffer), cpu = image::composite(plate, flare);
    ASSERT_EQ(gpu.size(), cpu.size());
    int differing = 0;
    for (std::size_t i = 0; i < n; ++i)
        if (std::memcmp(&gpu[i], &cpu[i], sizeof(float)) != 0 && ++differing <= 5)
            ADD_FAILURE() << "value " << i << ": plate " << plate[i] << " + flare " << flare[i] << ": gl " << gpu[i]
                          << ", cpu " << cpu[i];
    EXPECT_EQ(differing, 0);
    // Where the flare is zero the composite is the plate, bits and all.
    for (std::size_t i = 0; i < n; i += 3) EXPECT_EQ(std::memcmp(&cpu[i], &plate[i], sizeof(float)), 0) << i;
}

TEST(GlComposite, RefusesMismatchedSizes) {
    std::string why;
    const auto context = GlContext::create(why);
    if (!context) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    GlCompositor gl(*context);
    Buffer flare;
    flare.zeros(3 * 4 * 4 * sizeof(float));
    EXPECT_THROW(gl.composite(std::vector<float>(3 * 4 * 5), 4, 5, flare), Error);
    EXPECT_THROW(gl.composite(std::vector<float>(3), gl.maxSide() + 1, 1, flare), Error);
}

} // namespace
} // namespace ff::gpu
