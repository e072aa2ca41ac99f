// The guarded plate read (image/plate.h): the checker process, its wall-clock bounds and what each
// way of failing becomes. A fake checker (a shell script) plays each part.
#include "core/error.h"
#include "image/plate.h"

#include <OpenEXR/ImfRgbaFile.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "test_support.h"

using namespace ff;
namespace fs = std::filesystem;

namespace {

// A checker that runs `body` (sh), and a small RGBA EXR beside it for the read that follows.
struct Guard {
    ff::test::TempDir dir;
    image::PlateLimits limits;
    std::string plate = (dir / "plate.exr").string();

    explicit Guard(const std::string& body) {
        const fs::path script = dir / "checker";
        ff::test::writeFile(script, "#!/bin/sh\n" + body + "\n");
        fs::permissions(script, fs::perms::owner_all);
        limits.checker = script.string();
        const int W = 4, H = 3;
        std::vector<Imf::Rgba> px(W * H, Imf::Rgba(1.0f, 2.0f, 3.0f, 1.0f));
        Imf::RgbaOutputFile out(plate.c_str(), Imf::Header(W, H), Imf::WRITE_RGBA);
        out.setFrameBuffer(px.data(), 1, W);
        out.writePixels(H);
    }

    // The message of the error the read throws, and the seconds it took.
    std::pair<std::string, double> failure() const {
        const auto start = std::chrono::steady_clock::now();
        std::string message;
        try {
            (void)image::readPlate(plate, limits);
            ADD_FAILURE() << "the read succeeded";
        } catch (const Error& e) {
            EXPECT_EQ(e.kind(), ErrorKind::Input);
            message = e.what();
        }
        return {message, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
    }
};

} // namespace

TEST(PlateGuard, ACheckerHangingBeforeTheHeaderIsKilledAfterTheHeaderBound) {
    Guard g("exec sleep 60");
    g.limits.headerSeconds = 0.5;
    const auto [message, seconds] = g.failure();
    EXPECT_NE(message.find("reading the image's header did not finish within 0.5 s"), std::string::npos) << message;
    EXPECT_GE(seconds, 0.5);
    EXPECT_LT(seconds, 5.0);
}

TEST(PlateGuard, AHeaderThatPassedExtendsTheBoundByThePixelsSize) {
    // 3e6 bytes of float pixels at 1e6 bytes/s: the bound is 0.4 s after the header line, plus 3 s.
    Guard g("echo 'header 3000000'; exec sleep 60");
    g.limits.headerSeconds = 0.4;
    g.limits.floatBytesPerSecond = 1e6;
    const auto [message, seconds] = g.failure();
    EXPECT_NE(message.find("reading the image's pixels did not finish within 3.4 s"), std::string::npos) << message;
    EXPECT_GE(seconds, 3.4);
    EXPECT_LT(seconds, 8.0);
}

TEST(PlateGuard, ACrashOrAFailureOfTheCheckerIsAnInputErrorNamingTheFile) {
    {
        Guard g("kill -SEGV $$");
        const auto [message, seconds] = g.failure();
        EXPECT_NE(message.find(g.plate + ": the image library crashed reading this file (signal 11)"),
                  std::string::npos)
            << message;
    }
    {
        Guard g("echo 'the image is 9 x 9 = 81 pixels, above the limit' >&2; exit 3");
        const auto [message, seconds] = g.failure();
        EXPECT_NE(message.find(g.plate + ": the image is 9 x 9 = 81 pixels, above the limit"), std::string::npos)
            << message;
    }
    {
        Guard g("exit 7");
        const auto [message, seconds] = g.failure();
        EXPECT_NE(message.find("failed reading this file (exit status 7)"), std::string::npos) << message;
    }
}

TEST(PlateGuard, ACheckerThatPassesLetsThePlateBeRead) {
    Guard g("echo 'header 192'; exit 0");
    const image::Plate p = image::readPlate(g.plate, g.limits);
    EXPECT_EQ(p.width, 4);
    EXPECT_EQ(p.height, 3);
    EXPECT_FLOAT_EQ(p.value(5, p.b), 3.0f);
}
