#include "image/image_output.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>

#include "test_support.h"

using namespace ff;

namespace {

std::string bytesOf(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

} // namespace

TEST(ExrWriting, SameBytesOnOneAndTwoThreads) {
    // Nine channels as simulate writes them, over many zip chunks (16 scanlines each).
    const int W = 301, H = 203;
    std::vector<float> px(static_cast<std::size_t>(W) * H * 9);
    for (std::size_t i = 0; i < px.size(); ++i)
        px[i] = static_cast<float>(std::sin(0.001 * static_cast<double>(i)) * 100.0);
    const std::vector<std::string> names = {"R",       "G",           "B",           "flare.R",    "flare.G",
                                            "flare.B", "composite.R", "composite.G", "composite.B"};
    ff::test::TempDir dir;
    image::setExrThreads(1);
    image::writeExr((dir / "one.exr").string(), W, H, names, px, {{"fourierflare:note", "x"}});
    image::setExrThreads(2);
    image::writeExr((dir / "two.exr").string(), W, H, names, px, {{"fourierflare:note", "x"}});
    const std::string a = bytesOf(dir / "one.exr"), b = bytesOf(dir / "two.exr");
    ASSERT_GT(a.size(), 1000u);
    EXPECT_TRUE(a == b);
}
