// simulate as a shot meets it: a plate that already holds a channel of a layer it would add (its own
// output read again) is refused as soon as it is read, before the frame's flare is computed; the
// program's file replaced or removed during a shot (a package upgrade) does not stop the next frame.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>

#include "cli_runner.h"
#include "test_support.h"

using ff::test::run;
namespace fs = std::filesystem;

namespace {

// A 64 x 48 float plate with channels R, G, B and `extra`, a light of 1e4 at (20, 12).
void writePlate(const fs::path& path, const std::string& extra) {
    const int W = 64, H = 48, C = 4;
    std::vector<float> px(static_cast<std::size_t>(W) * H * C, 0.1f);
    for (int c = 0; c < 3; ++c) px[(static_cast<std::size_t>(12) * W + 20) * C + c] = 1e4f;
    OIIO::ImageSpec spec(W, H, C, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", extra};
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out && out->open(path.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) &&
                out->close());
}

std::size_t filesUnder(const fs::path& dir) {
    std::size_t n = 0;
    if (fs::exists(dir))
        for (const auto& e : fs::recursive_directory_iterator(dir)) n += e.is_regular_file();
    return n;
}

} // namespace

// The plate holds ghosts.G: the default layers (ghosts, diffraction) are refused, exit 2 naming the
// plate and the channel, nothing written and nothing computed (the run's own cache stays empty: no
// ghost table was built); --layers diffraction,flare leaves it alone.
TEST(CliSimulate, APlateHoldingALayersChannelIsRefusedBeforeTheWork) {
    ff::test::TempDir dir;
    const fs::path plate = dir / "plate.exr", out = dir / "out.exr", cache = dir / "cache";
    writePlate(plate, "ghosts.G");
    const std::string args = "simulate --lens lenses/cooke-triplet-50mm-f5.lens --sensor-size 3x2.25 --plate '" +
                             plate.string() + "' -o '" + out.string() + "'";
    const auto refused = run(args, "FF_CACHE_DIR='" + cache.string() + "'");
    EXPECT_EQ(refused.code, 2) << refused.err;
    EXPECT_NE(refused.err.find(plate.string() + ": the plate already has a channel ghosts.G"), std::string::npos)
        << refused.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(filesUnder(cache), 0u);

    const auto other =
        run(args + " --layers diffraction,flare", std::string("FF_CACHE_DIR='") + FF_TEST_CACHE_DIR + "'");
    ASSERT_EQ(other.code, 0) << other.err;
    EXPECT_TRUE(fs::exists(out));
}

// The plate checker is the running program: a copy of fourierflare, removed once it runs (its
// /proc/PID/exe names the copy), still renders both frames of a sequence: each spawns its checker
// after the file is gone.
TEST(CliSimulate, TheProgramRemovedDuringAShotStillChecksThePlates) {
    ff::test::TempDir dir;
    for (const char* f : {"plate.0001.exr", "plate.0002.exr"}) writePlate(dir / f, "A");
    const fs::path copy = dir / "ff-copy";
    fs::copy_file(FF_CLI_PATH, copy);
    std::ofstream(dir / "shot.sh") << "cd '" << FF_SOURCE_DIR << "'\nFF_CACHE_DIR='" << FF_TEST_CACHE_DIR << "' '"
                                   << copy.string()
                                   << "' simulate --lens lenses/cooke-triplet-50mm-f5.lens --sensor-size 3x2.25 "
                                      "--frames 1-2 --plate '"
                                   << (dir / "plate.%04d.exr").string() << "' -o '" << (dir / "out.%04d.exr").string()
                                   << "' 2>'" << (dir / "err").string()
                                   << "' &\npid=$!\nfor i in $(seq 1000); do\n  [ \"$(readlink /proc/$pid/exe)\" = '"
                                   << copy.string() << "' ] && break\n  sleep 0.001\ndone\nrm '" << copy.string()
                                   << "'\nwait $pid\n";
    const int status = std::system(("bash '" + (dir / "shot.sh").string() + "'").c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << ff::test::readFile(dir / "err");
    EXPECT_FALSE(fs::exists(copy));
    EXPECT_TRUE(fs::exists(dir / "out.0001.exr"));
    EXPECT_TRUE(fs::exists(dir / "out.0002.exr"));
}
