// The same command on the same inputs writes the same bytes: across runs (a second apart, so a time
// of writing would differ), across 1 and 2 threads, and with SOURCE_DATE_EPOCH's time stamp.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "cli_runner.h"
#include "test_support.h"

using ff::test::run;
namespace fs = std::filesystem;

namespace {

const std::string kEnv = std::string("FF_CACHE_DIR='") + FF_TEST_CACHE_DIR + "' ";

std::string q(const fs::path& p) {
    return "'" + p.string() + "'";
}

// A float RGB plate without a time stamp: a dim gradient and one bright 2 x 2 light.
void writePlate(const fs::path& path) {
    constexpr int W = 80, H = 48;
    std::vector<float> rgb(static_cast<std::size_t>(W) * H * 3);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int c = 0; c < 3; ++c) {
                const bool light = x >= 50 && x < 52 && y >= 20 && y < 22;
                rgb[(static_cast<std::size_t>(y) * W + x) * 3 + c] = light ? 500.0f : 0.01f * float(c + 1);
            }
    OIIO::ImageSpec spec(W, H, 3, OIIO::TypeDesc::FLOAT);
    spec.attribute("DateTime", ""); // an empty DateTime is left out of the file
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out && out->open(path.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()) &&
                out->close());
}

std::string dateTimeOf(const fs::path& path) {
    auto in = OIIO::ImageInput::open(path.string());
    EXPECT_TRUE(in) << path;
    return in ? in->spec().get_string_attribute("DateTime", "<none>") : "";
}

// Runs `args` (which write `outputs` inside `dir`) under `prefix` (environment and global options)
// and returns the outputs' bytes, the files then removed.
std::vector<std::string> outputsOf(const std::string& prefix, const std::string& args,
                                   const std::vector<fs::path>& outputs) {
    const auto r = run(prefix + args, kEnv);
    EXPECT_EQ(r.code, 0) << r.err;
    std::vector<std::string> bytes;
    for (const fs::path& p : outputs) {
        bytes.push_back(ff::test::readFile(p));
        EXPECT_FALSE(bytes.back().empty()) << p;
        fs::remove(p);
    }
    return bytes;
}

void expectSameBytesAcrossRunsAndThreads(const std::string& args, const std::vector<fs::path>& outputs) {
    const auto first = outputsOf("--threads 1 ", args, outputs);
    for (const fs::path& p : outputs) EXPECT_FALSE(fs::exists(p));
    std::this_thread::sleep_for(std::chrono::milliseconds(1100)); // a time of writing would change
    const auto again = outputsOf("--threads 1 ", args, outputs);
    const auto two = outputsOf("--threads 2 ", args, outputs);
    const auto all = outputsOf("", args, outputs);
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        EXPECT_TRUE(first[i] == again[i]) << outputs[i] << ": two runs differ";
        EXPECT_TRUE(first[i] == two[i]) << outputs[i] << ": 1 and 2 threads differ";
        EXPECT_TRUE(first[i] == all[i]) << outputs[i] << ": 1 thread and all cores differ";
    }
}

} // namespace

TEST(CliReproducible, RenderWritesTheSameBytes) {
    ff::test::TempDir dir;
    const fs::path exr = dir / "flare.exr", png = dir / "flare.png";
    const std::string args =
        "render --lens lenses/cooke-triplet-50mm-f5.lens --light 60,20 --size 96x64 --mode fourier "
        "-o " +
        q(exr) + " --preview " + q(png);
    expectSameBytesAcrossRunsAndThreads(args, {exr, png});
    // No time stamp without SOURCE_DATE_EPOCH.
    ASSERT_EQ(run(args, kEnv).code, 0);
    EXPECT_EQ(dateTimeOf(exr), "<none>");
}

TEST(CliReproducible, SimulateWritesTheSameBytes) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr");
    const fs::path exr = dir / "out.exr", png = dir / "out.png", flare = dir / "flare.png";
    const std::string args = "simulate --lens lenses/cooke-triplet-50mm-f5.lens --plate " + q(dir / "plate.exr") +
                             " -o " + q(exr) + " --preview " + q(png) + " --preview-flare " + q(flare);
    expectSameBytesAcrossRunsAndThreads(args, {exr, png, flare});
    ASSERT_EQ(run(args, kEnv).code, 0);
    EXPECT_EQ(dateTimeOf(exr), "<none>");
}

TEST(CliReproducible, SourceDateEpochSetsTheTimeStamp) {
    ff::test::TempDir dir;
    const fs::path exr = dir / "flare.exr";
    const std::string args =
        "render --lens lenses/cooke-triplet-50mm-f5.lens --light 60,20 --size 64x48 --mode fitted -o " + q(exr);
    // 1700000000 s after the epoch: 19675 days (2023-11-14) and 80000 s (22:13:20), UTC.
    ASSERT_EQ(run(args, kEnv + "SOURCE_DATE_EPOCH=1700000000 TZ=Pacific/Auckland").code, 0);
    EXPECT_EQ(dateTimeOf(exr), "2023:11:14 22:13:20");
    const std::string stamped = ff::test::readFile(exr);
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));
    ASSERT_EQ(run(args, kEnv + "SOURCE_DATE_EPOCH=1700000000").code, 0);
    EXPECT_TRUE(ff::test::readFile(exr) == stamped);
    fs::remove(exr);
    // Anything but digits is refused before any work: exit 2, no output.
    for (const std::string bad : {"yesterday", "-5", "1.5", "12 ", "99999999999999999999"}) {
        const auto r = run(args, kEnv + "SOURCE_DATE_EPOCH='" + bad + "'");
        EXPECT_EQ(r.code, 2) << bad;
        EXPECT_NE(r.err.find("SOURCE_DATE_EPOCH"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(exr)) << bad;
    }
}
