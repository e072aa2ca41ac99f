#include "core/error.h"
#include "image/image_output.h"
#include "image/plate.h"

#include <OpenEXR/ImfRgbaFile.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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
    // The header's DateTime, which OpenImageIO otherwise sets to the time of writing, is given: two
    // writes a second apart would differ there.
    const image::Metadata meta = {{"fourierflare:note", "x"}, {"DateTime", "2026:01:01 00:00:00"}};
    image::setExrThreads(1);
    image::writeExr((dir / "one.exr").string(), W, H, names, px, meta);
    image::setExrThreads(2);
    image::writeExr((dir / "two.exr").string(), W, H, names, px, meta);
    const std::string a = bytesOf(dir / "one.exr"), b = bytesOf(dir / "two.exr");
    ASSERT_GT(a.size(), 1000u);
    EXPECT_TRUE(a == b);
}

TEST(PlateReading, ALuminanceChromaPlateReadsAsRgb) {
    // OpenEXR's luminance/chroma encoding stores Y at full resolution and RY = (R - Y) / Y,
    // BY = (B - Y) / Y subsampled 2 x 2. One hue at varying brightness has constant RY and BY, so the
    // subsampling loses nothing and RGB must come back within half-float rounding (a few 1e-3).
    const int W = 38, H = 22; // even: the chroma is subsampled 2 x 2
    std::vector<Imf::Rgba> px(static_cast<std::size_t>(W) * H);
    auto rgbAt = [](int x, int y) {
        const float k = 0.2f + 3.0f * static_cast<float>(x + 2 * y) / (W + 2 * H);
        return std::array<float, 3>{0.8f * k, 0.5f * k, 0.2f * k};
    };
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const auto c = rgbAt(x, y);
            px[static_cast<std::size_t>(y) * W + x] = Imf::Rgba(c[0], c[1], c[2], 1.0f);
        }
    ff::test::TempDir dir;
    const std::string path = (dir / "yc.exr").string();
    {
        Imf::Header header(W, H);
        Imf::RgbaOutputFile out(path.c_str(), header, Imf::WRITE_YC);
        out.setYCRounding(10, 10); // keep all of half's mantissa (the default rounds chroma to 5 bits)
        out.setFrameBuffer(px.data(), 1, W);
        out.writePixels(H);
    }
    const image::Plate plate = image::readPlate(path);
    ASSERT_EQ(plate.width, W);
    ASSERT_EQ(plate.height, H);
    EXPECT_EQ(plate.channels, (std::vector<std::string>{"R", "G", "B"}));
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const auto c = rgbAt(x, y);
            const std::size_t i = static_cast<std::size_t>(y) * W + x;
            EXPECT_NEAR(plate.value(i, plate.r), c[0], 4e-3 * c[0]) << x << "," << y;
            EXPECT_NEAR(plate.value(i, plate.g), c[1], 4e-3 * c[1]) << x << "," << y;
            EXPECT_NEAR(plate.value(i, plate.b), c[2], 4e-3 * c[2]) << x << "," << y;
        }
    ASSERT_FALSE(plate.notes.empty());
    EXPECT_NE(plate.notes.back().find("luminance/chroma"), std::string::npos);
    // And simulate's writer keeps the converted channels beside the flare layers.
    const std::vector<float> flare(plate.pixelCount() * 3, 0.0f);
    const std::vector<float> composite = plate.rgb();
    image::writeSimulatedExr((dir / "out.exr").string(), plate, {{"flare", &flare}, {"composite", &composite}}, {});
    const image::Plate back = image::readPlate((dir / "out.exr").string());
    EXPECT_EQ(back.channels.size(), 9u);
    EXPECT_EQ(back.value(5, back.r), plate.value(5, plate.r));
}

// A plate that already holds a layer's channel (one written by simulate, read again) is refused
// before anything is written: EXR channel names are unique, and the writer would rename one of them.
TEST(PlateWriting, ALayerThatThePlateAlreadyHoldsIsRefused) {
    ff::test::TempDir dir;
    const std::string in = (dir / "in.exr").string(), out = (dir / "out.exr").string();
    {
        OIIO::ImageSpec spec(4, 3, 4, OIIO::TypeDesc::FLOAT);
        spec.channelnames = {"R", "G", "B", "flare.G"};
        const std::vector<float> px(4 * 3 * 4, 0.5f);
        auto o = OIIO::ImageOutput::create(in);
        ASSERT_TRUE(o && o->open(in, spec) && o->write_image(OIIO::TypeDesc::FLOAT, px.data()) && o->close());
    }
    const image::Plate plate = image::readPlate(in);
    const std::vector<float> rgb(plate.pixelCount() * 3, 1.0f);
    try {
        image::writeSimulatedExr(out, plate, {{"flare", &rgb}}, {});
        ADD_FAILURE() << "written";
    } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Input);
        EXPECT_NE(std::string(e.what()).find("already has a channel flare.G"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(out));
    // Another layer name is fine, and every channel keeps its name.
    image::writeSimulatedExr(out, plate, {{"ghosts", &rgb}}, {});
    EXPECT_EQ(image::readPlate(out).channels,
              (std::vector<std::string>{"R", "G", "B", "flare.G", "ghosts.R", "ghosts.G", "ghosts.B"}));
}

// Desqueezing a preview: each output pixel centre (i + 0.5) samples the input at (i + 0.5) / factor
// pixels, linearly between input centres, so a ramp v = x (x the pixel centre, j + 0.5) stays the ramp
// v = (i + 0.5) / factor inside and holds its end values beyond the outer centres.
TEST(PreviewStretch, ARampStretchesToTheRampAtTheNewCentres) {
    const int W = 5, H = 2;
    std::vector<float> rgb(static_cast<std::size_t>(W) * H * 3);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int c = 0; c < 3; ++c)
                rgb[(static_cast<std::size_t>(y) * W + x) * 3 + c] = static_cast<float>((x + 0.5) * (c + 1));
    int w = 0;
    const std::vector<float> out = image::stretchedRows(rgb, W, H, 2.0, &w);
    ASSERT_EQ(w, 10);
    ASSERT_EQ(out.size(), static_cast<std::size_t>(w) * H * 3);
    for (int y = 0; y < H; ++y)
        for (int i = 0; i < w; ++i) {
            const double x = std::clamp((i + 0.5) / 2.0, 0.5, W - 0.5);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(out[(static_cast<std::size_t>(y) * w + i) * 3 + c], x * (c + 1), 1e-6) << i;
        }
    EXPECT_THROW(image::stretchedRows(rgb, W, H, 0.0, &w), Error);
}
