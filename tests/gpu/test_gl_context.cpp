// Context lifetime: contexts share the process's EGL display, so destroying one must leave the
// others usable (it releases only itself and does not terminate the display).

#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <gtest/gtest.h>

#include <vector>

namespace ff::gpu {
namespace {

TEST(GlContext, OneOutlivesAnotherOnTheSameDisplay) {
    std::string why;
    auto first = GlContext::create(why);
    if (!first) GTEST_SKIP() << "no OpenGL 4.5 context: " << why;
    auto second = GlContext::create(why); // current from here on
    ASSERT_TRUE(second) << why;
    first.reset();
    const std::vector<float> in{1.5f, -2.0f, 3.25f, 1e30f};
    std::vector<float> out(in.size(), 0.0f);
    {
        Buffer b;
        b.upload(in.data(), in.size() * sizeof(float));
        b.download(out.data(), out.size() * sizeof(float));
    }
    EXPECT_EQ(out, in);
    EXPECT_NO_THROW(checkGl("a buffer round trip on the surviving context"));
}

} // namespace
} // namespace ff::gpu
