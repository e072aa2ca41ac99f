// simulate and render with dirt on the front element: --dirt SEED[,DENSITY] reproducible, an
// --aperture-mask image, and every bad mask or value refused (exit 2, naming it) before anything is
// written.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "cli_runner.h"
#include "test_support.h"

using ff::test::run;
namespace fs = std::filesystem;

namespace {

const std::string kEnv = std::string("FF_CACHE_DIR='") + FF_TEST_CACHE_DIR + "' ";

// width x height, channels per pixel, every value `fill`, and a 2 x 2 block of `light` at (20, 12).
void writeImage(const fs::path& path, int width, int height, int channels, float fill, float light = 0.0f) {
    std::vector<float> px(static_cast<std::size_t>(width) * height * channels, fill);
    for (int y = 12; y < 14 && light > 0.0f; ++y)
        for (int x = 20; x < 22; ++x)
            for (int c = 0; c < channels; ++c) px[(static_cast<std::size_t>(y) * width + x) * channels + c] = light;
    auto out = OIIO::ImageOutput::create(path.string());
    const OIIO::ImageSpec spec(width, height, channels,
                               path.extension() == ".png" ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    ASSERT_TRUE(out && out->open(path.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) &&
                out->close());
}

std::vector<float> channel(const fs::path& exr, const std::string& name) {
    auto in = OIIO::ImageInput::open(exr.string());
    if (!in) return {};
    const OIIO::ImageSpec spec = in->spec();
    std::vector<float> all(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
    in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data());
    const int c = spec.channelindex(name);
    std::vector<float> out;
    for (std::size_t p = 0; c >= 0 && p < static_cast<std::size_t>(spec.width) * spec.height; ++p)
        out.push_back(all[p * spec.nchannels + c]);
    return out;
}

std::string simulate(const fs::path& plate, const fs::path& out, const std::string& extra) {
    // A 3 mm sensor: 64 pixels of 47 um, so that the PSF's near field (where dirt acts) spans pixels.
    return "simulate --lens lenses/cooke-triplet-50mm-f5.lens --sensor-size 3x2.25 --plate '" + plate.string() +
           "' -o '" + out.string() + "' " + extra;
}

} // namespace

TEST(CliDirt, TheSameSeedGivesTheSameStarburstAndAMaskChangesIt) {
    ff::test::TempDir dir;
    writeImage(dir / "plate.exr", 64, 48, 3, 0.01f, 5000.0f);
    const auto clean = run(simulate(dir / "plate.exr", dir / "clean.exr", ""), kEnv);
    ASSERT_EQ(clean.code, 0) << clean.err;
    for (const char* name : {"a.exr", "b.exr"}) {
        const auto r = run(simulate(dir / "plate.exr", dir / name, "--dirt 7,2"), kEnv);
        ASSERT_EQ(r.code, 0) << r.err;
    }
    const auto a = channel(dir / "a.exr", "diffraction.G"), b = channel(dir / "b.exr", "diffraction.G");
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(a, b);
    EXPECT_NE(a, channel(dir / "clean.exr", "diffraction.G"));
    // A half-grey mask image (any size): runs, and differs from clean.
    writeImage(dir / "mask.png", 300, 200, 1, 0.5f);
    const auto m =
        run(simulate(dir / "plate.exr", dir / "m.exr", "--aperture-mask '" + (dir / "mask.png").string() + "'"), kEnv);
    ASSERT_EQ(m.code, 0) << m.err;
    auto in = OIIO::ImageInput::open((dir / "m.exr").string());
    ASSERT_TRUE(in);
    EXPECT_NE(in->spec().get_string_attribute("fourierflare:diffraction").find("dirt on the front element (mask 200"),
              std::string::npos);
}

TEST(CliDirt, BadMasksAndValuesExitTwoAndWriteNothing) {
    ff::test::TempDir dir;
    writeImage(dir / "plate.exr", 64, 48, 3, 0.01f, 5000.0f);
    ff::test::writeFile(dir / "empty.png", "");
    ff::test::writeFile(dir / "text.png", "not an image at all\n");
    // A header claiming 16384 x 16384 (above the masks' 8192 x 8192).
    writeImage(dir / "small.exr", 8, 8, 1, 1.0f);
    ASSERT_TRUE(ff::test::writeHugeHeaderCopy(dir / "small.exr", dir / "huge.exr"));
    const fs::path out = dir / "out.exr";
    for (const fs::path& bad : {dir / "missing.png", dir / "empty.png", dir / "text.png", dir / "huge.exr"}) {
        const auto r = run(simulate(dir / "plate.exr", out, "--aperture-mask '" + bad.string() + "'"), kEnv);
        EXPECT_EQ(r.code, 2) << bad << "\n" << r.err;
        EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(out)) << bad;
    }
    for (const char* bad : {"x", "-1", "7,0", "7,abc", "7,1e9", "99999999999999999999999"}) {
        const auto r = run(simulate(dir / "plate.exr", out, std::string("--dirt '") + bad + "'"), kEnv);
        EXPECT_EQ(r.code, 2) << bad << "\n" << r.err;
        EXPECT_NE(r.err.find("--dirt"), std::string::npos) << bad << "\n" << r.err;
        EXPECT_FALSE(fs::exists(out)) << bad;
    }
    // render --mode diffraction takes the same options.
    const auto r = run("render --lens lenses/cooke-triplet-50mm-f5.lens --mode diffraction --size 64x48 --light 20,12 "
                       "--dirt 3 -o '" +
                           (dir / "render.exr").string() + "'",
                       kEnv);
    EXPECT_EQ(r.code, 0) << r.err;
}
