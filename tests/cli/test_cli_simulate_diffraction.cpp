// `fourierflare simulate`'s diffraction: off, its gain, lights given by hand and beyond the frame,
// and the lens's traced wavefront per tile.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "cli_runner.h"
#include "simulate_support.h"
#include "test_support.h"

using ff::test::run;
using namespace ff::test::simulate;

// --diffraction off leaves the ghosts alone; --diffraction-gain scales the light the iris spreads
// (away from the lights' own pixels, where a pixel never gives more than its light); lights given by
// hand are diffracted where they are; bad values are refused.
TEST(CliSimulate, DiffractionOffGainAndLightsGivenByHand) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr", -1, -1, 0.0f);
    const std::string light = " --layers ghosts,diffraction,lights,flare --light 40.5,30.5,5000,5000,5000";
    ASSERT_EQ(run(simulate(dir / "plate.exr", dir / "off.exr", "--diffraction off" + light), kEnv).code, 0);
    ASSERT_EQ(run(simulate(dir / "plate.exr", dir / "one.exr", light), kEnv).code, 0);
    ASSERT_EQ(run(simulate(dir / "plate.exr", dir / "two.exr", "--diffraction-gain 2" + light), kEnv).code, 0);
    const Exr off = readExr(dir / "off.exr"), one = readExr(dir / "one.exr"), two = readExr(dir / "two.exr");
    EXPECT_EQ(off.spec.get_string_attribute("fourierflare:diffraction"), "off");
    const int d = one.channel("diffraction.G"), f = one.channel("flare.G"), g = one.channel("ghosts.G"),
              l = one.channel("lights.G");
    ASSERT_TRUE(d >= 0 && f >= 0 && g >= 0 && l >= 0);
    const std::size_t lightPixel = static_cast<std::size_t>(30) * kW + 40;
    double sum = 0.0, spread = 0.0;
    for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) {
        ASSERT_EQ(off.at(p, d), 0.0f);
        ASSERT_EQ(off.at(p, l), 0.0f);
        ASSERT_EQ(off.at(p, f), off.at(p, g));
        ASSERT_EQ(one.at(p, g), off.at(p, g));                     // the ghosts do not depend on the diffraction
        ASSERT_EQ(one.at(p, l), p == lightPixel ? 5000.0f : 0.0f); // the light given, in its pixel
        sum += one.at(p, d);
        if (p != lightPixel) {
            spread += one.at(p, d);
            EXPECT_NEAR(two.at(p, d), 2.0f * one.at(p, d), 1e-5f * 5000.0f) << p;
        }
    }
    // What the pattern holds left the light's pixel.
    EXPECT_NEAR(one.at(lightPixel, d), 5000.0 - spread, 1e-4 * 5000.0);
    EXPECT_NEAR(two.at(lightPixel, d), 5000.0 - 2.0 * spread, 1e-4 * 5000.0);
    EXPECT_NEAR(sum, 5000.0, 1e-4 * 5000.0);
    EXPECT_GT(spread, 0.0);
    for (const std::string bad : {"--diffraction-gain -1", "--diffraction-gain nan", "--diffraction bogus"})
        EXPECT_EQ(run(simulate(dir / "plate.exr", dir / "bad.exr", bad + light), kEnv).code, 2) << bad;
    EXPECT_FALSE(fs::exists(dir / "bad.exr"));
}

// A light given beyond the frame (a sun just off its left edge) casts its spikes into it: the
// diffraction layer holds light in the frame, the lights layer none (the plate does not hold it), and
// the flux that reaches in is a small part of the light's, more of it near the edge it lies beyond.
TEST(CliSimulate, ALightGivenBeyondTheFrameReachesIntoIt) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr", -1, -1, 0.0f);
    const std::string light = " --layers diffraction,lights --light -6.5,32.5,1e6,1e6,1e6";
    const auto r = run(simulate(dir / "plate.exr", dir / "out.exr", light), kEnv);
    ASSERT_EQ(r.code, 0) << r.err;
    const Exr e = readExr(dir / "out.exr");
    const int d = e.channel("diffraction.G"), l = e.channel("lights.G");
    double sum = 0.0, nearEdge = 0.0, farEdge = 0.0;
    for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) {
        ASSERT_EQ(e.at(p, l), 0.0f);
        ASSERT_GE(e.at(p, d), 0.0f);
        sum += e.at(p, d);
        (p % kW < static_cast<std::size_t>(kW) / 2 ? nearEdge : farEdge) += e.at(p, d);
    }
    EXPECT_GT(sum, 0.0);
    EXPECT_LT(sum, 0.5 * 1e6);
    EXPECT_GT(nearEdge, farEdge);
}

// --diffraction traced: the PSF carries the lens's traced wavefront per tile holding light; the
// layer still only moves the lights' flux (sums to theirs), the ghosts do not change, and the f/5
// triplet's aberrations near the frame's corner spread more of it out of the light's pixel than
// the aberration-free PSF does.
TEST(CliSimulate, DiffractionTracedUsesTheLensWavefrontPerTile) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr", -1, -1, 0.0f);
    const std::string lights = " --light 48.5,32.5,5000,5000,5000 --light 90.5,5.5,5000,5000,5000";
    ASSERT_EQ(run(simulate(dir / "plate.exr", dir / "ideal.exr", "--sensor-size 36x24" + lights), kEnv).code, 0);
    const auto r =
        run(simulate(dir / "plate.exr", dir / "traced.exr", "--sensor-size 36x24 --diffraction traced" + lights), kEnv);
    ASSERT_EQ(r.code, 0) << r.err;
    const Exr ideal = readExr(dir / "ideal.exr"), traced = readExr(dir / "traced.exr");
    const std::string meta = traced.spec.get_string_attribute("fourierflare:diffraction");
    EXPECT_NE(meta.find("traced, gain 1"), std::string::npos) << meta;
    EXPECT_NE(meta.find("48,32: to"), std::string::npos) << meta; // the tiles' centres, one light each
    EXPECT_NE(meta.find("90,6: to"), std::string::npos) << meta;
    const int d = traced.channel("diffraction.G"), g = traced.channel("ghosts.G");
    double sum = 0.0;
    for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) {
        ASSERT_EQ(traced.at(p, g), ideal.at(p, g));
        sum += traced.at(p, d);
    }
    EXPECT_NEAR(sum, 10000.0, 1e-4 * 10000.0); // the two lights' flux
    const std::size_t corner = static_cast<std::size_t>(5) * kW + 90;
    EXPECT_LT(traced.at(corner, d), ideal.at(corner, d)); // more of the light leaves its pixel
}
