// The guarded plate read (image/plate.h): the checker process, its CPU and wall-clock bounds and what each
// way of failing becomes. A fake checker (a shell script) plays each part.
#include "core/error.h"
#include "image/plate.h"

#include <OpenEXR/ImfRgbaFile.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
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

TEST(PlateGuard, ACheckerStuckWithoutSpendingCpuTimeIsKilledAfterTheWallClockBound) {
    // 0.05 s of CPU time, 10 times that of wall-clock time: sleep spends none, so the wall bound fires,
    // and as a stuck checker is no evidence of a bad file, it is not an input error.
    Guard g("exec sleep 60");
    g.limits.cpuSeconds = 0.05;
    g.limits.wallFactor = 10.0;
    const auto start = std::chrono::steady_clock::now();
    try {
        (void)image::readPlate(g.plate, g.limits);
        ADD_FAILURE() << "the read succeeded";
    } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Runtime);
        const std::string m = e.what();
        EXPECT_NE(m.find("reading the image's header did not finish within 0.5 s, having spent "), std::string::npos)
            << m;
        EXPECT_NE(m.find(" of its 0.05 s of CPU time: it waited"), std::string::npos) << m;
        EXPECT_NE(m.find("FF_PLATE_CHECK_SECONDS raises the bound"), std::string::npos) << m;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_GE(seconds, 0.5);
    EXPECT_LT(seconds, 5.0);
}

TEST(PlateGuard, ACheckerInALoopIsKilledByItsCpuTimeNotTheWallClock) {
    // A busy loop before the header: killed once it has spent 0.3 s of CPU time, long before the
    // wall-clock bound of 100 times that.
    Guard g("while :; do :; done");
    g.limits.cpuSeconds = 0.3;
    g.limits.wallFactor = 100.0;
    const auto [message, seconds] = g.failure();
    EXPECT_NE(message.find("reading the image's header spent "), std::string::npos) << message;
    EXPECT_NE(
        message.find(" s of CPU time without finishing, more than its 0.3 s: the image library is stuck in a loop"),
        std::string::npos)
        << message;
    EXPECT_GE(seconds, 0.3);
    EXPECT_LT(seconds, 10.0);
}

TEST(PlateGuard, ACheckerSlowerInWallClockTimeThanItsCpuBoundPasses) {
    // What a loaded machine does to a valid file: the checker waits (here 1 s asleep) far longer than
    // its CPU bound (0.2 s) while spending almost none of it, and the plate is read.
    Guard g("sleep 1; echo 'header 192'; exit 0");
    g.limits.cpuSeconds = 0.2;
    g.limits.wallFactor = 20.0;
    const image::Plate p = image::readPlate(g.plate, g.limits);
    EXPECT_EQ(p.width, 4);
}

TEST(PlateGuard, AHeaderThatPassedExtendsTheBoundsByThePixelsSize) {
    {
        // 3e6 bytes of float pixels at 1e6 bytes/s: the wall-clock bound (factor 1) is 0.04 + 3 s after
        // the header line.
        Guard g("echo 'header 3000000'; exec sleep 60");
        g.limits.cpuSeconds = 0.04;
        g.limits.floatBytesPerSecond = 1e6;
        g.limits.wallFactor = 1.0;
        const auto start = std::chrono::steady_clock::now();
        try {
            (void)image::readPlate(g.plate, g.limits);
            ADD_FAILURE() << "the read succeeded";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("reading the image's pixels did not finish within 3."),
                      std::string::npos)
                << e.what();
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_GE(seconds, 3.04);
        EXPECT_LT(seconds, 8.0);
    }
    {
        // The CPU bound: 0.1 s plus 3e6 bytes at 1e7 bytes/s = 0.4 s more once the header has passed.
        Guard g("echo 'header 3000000'; while :; do :; done");
        g.limits.cpuSeconds = 0.1;
        g.limits.floatBytesPerSecond = 1e7;
        g.limits.wallFactor = 100.0;
        const auto [message, seconds] = g.failure();
        EXPECT_NE(message.find("reading the image's pixels spent "), std::string::npos) << message;
        EXPECT_NE(message.find(" s of CPU time without finishing, more than its 0.4 s"), std::string::npos) << message;
        EXPECT_GE(seconds, 0.4);
        EXPECT_LT(seconds, 15.0);
    }
}

TEST(PlateGuard, TheCpuBoundComesFromTheEnvironment) {
    struct Restore {
        ~Restore() { unsetenv("FF_PLATE_CHECK_SECONDS"); }
    } restore;
    unsetenv("FF_PLATE_CHECK_SECONDS");
    EXPECT_EQ(image::plateCheckSeconds(), image::kPlateCheckSeconds);
    setenv("FF_PLATE_CHECK_SECONDS", "12.5", 1);
    EXPECT_EQ(image::plateCheckSeconds(), 12.5);
    for (const char* bad : {"abc", "3s", "0", "-1", "1e9", "nan"}) {
        setenv("FF_PLATE_CHECK_SECONDS", bad, 1);
        try {
            (void)image::plateCheckSeconds();
            ADD_FAILURE() << bad << " was taken";
        } catch (const Error& e) {
            EXPECT_EQ(e.kind(), ErrorKind::Usage);
            EXPECT_NE(std::string(e.what()).find("FF_PLATE_CHECK_SECONDS is '" + std::string(bad) + "'"),
                      std::string::npos)
                << e.what();
        }
    }
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
