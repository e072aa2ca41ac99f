// `fourierflare simulate` on small generated plates, the shared real plates and the damaged corpus.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <Imath/half.h>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "cli_runner.h"
#include "simulate_support.h"
#include "test_support.h"

using ff::test::run;
namespace fs = std::filesystem;

using namespace ff::test::simulate;

TEST(CliSimulate, KeepsEveryChannelAndAddsFlareLayers) {
    ff::test::TempDir dir;
    const TestPlate plate = writePlate(dir / "plate.exr", 20, 12, 400.0f, 3, 2);
    const auto r = run(simulate(dir / "plate.exr", dir / "out.exr",
                                "--layers all --preview '" + (dir / "out.png").string() + "' --lights-out '" +
                                    (dir / "lights.json").string() + "'"),
                       kEnv);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("1 lights above luminance"), std::string::npos) << r.err;
    const Exr e = readExr(dir / "out.exr");
    ASSERT_EQ(e.spec.nchannels, 20); // R G B A Z + ghosts, diffraction, lights, flare, composite
    EXPECT_EQ(e.spec.x, 3);
    EXPECT_EQ(e.spec.y, 2);
    EXPECT_EQ(e.spec.full_width, kW + 6);
    EXPECT_EQ(e.spec.get_string_attribute("studio:shot"), "sq010_sh020");
    EXPECT_NE(e.spec.get_string_attribute("fourierflare:lensHash"), "");
    EXPECT_NE(e.spec.get_string_attribute("fourierflare:commandLine").find("simulate"), std::string::npos);
    EXPECT_EQ(e.spec.get_string_attribute("fourierflare:ghostModel"), "shaped");
    EXPECT_NE(e.spec.get_string_attribute("fourierflare:culled").find("of a light's ghost flux"), std::string::npos);
    // Input channels bit for bit (half values read back as float are exact) and in their formats.
    const int R = e.channel("R"), A = e.channel("A"), Z = e.channel("Z"), fR = e.channel("flare.R"),
              cR = e.channel("composite.R"), gR = e.channel("ghosts.R"), dR = e.channel("diffraction.R"),
              lR = e.channel("lights.R");
    ASSERT_TRUE(R >= 0 && A >= 0 && Z >= 0 && fR >= 0 && cR >= 0 && gR >= 0 && dR >= 0 && lR >= 0);
    EXPECT_EQ(e.spec.channelformat(R), OIIO::TypeDesc::HALF);
    EXPECT_EQ(e.spec.channelformat(Z), OIIO::TypeDesc::FLOAT);
    auto asHalf = [](float v) { return static_cast<float>(static_cast<Imath::half>(v)); };
    double ghosts = 0.0, diffraction = 0.0, lit = 0.0, spread = 0.0, cores = 0.0;
    for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) {
        ASSERT_EQ(e.at(p, R), asHalf(plate.rgba[p * 4]));
        ASSERT_EQ(e.at(p, A), asHalf(plate.rgba[p * 4 + 3]));
        ASSERT_EQ(e.at(p, Z), plate.z[p]);
        ASSERT_EQ(e.at(p, fR), e.at(p, gR) + e.at(p, dR)); // flare = ghosts + diffraction
        // composite = plate + flare - lights, to float rounding.
        const double c = e.at(p, R) + e.at(p, fR) - e.at(p, lR);
        ASSERT_NEAR(e.at(p, cR), c, 1e-6 * (std::abs(e.at(p, R)) + e.at(p, fR) + e.at(p, lR)) + 1e-30);
        // Every layer but the composite is >= 0; the lights layer is the light's pixels of the plate.
        ASSERT_GE(e.at(p, gR), 0.0f);
        ASSERT_GE(e.at(p, dR), 0.0f);
        ASSERT_TRUE(e.at(p, lR) == 0.0f || e.at(p, lR) == e.at(p, R)) << p;
        ghosts += e.at(p, gR);
        diffraction += e.at(p, dR);
        lit += e.at(p, lR);
        (e.at(p, lR) > 0.0f ? cores : spread) += e.at(p, dR);
    }
    EXPECT_GT(ghosts, 0.0);
    // The diffraction draws the light's flux (4 x 400 in R) again, spread by the iris (how far:
    // tests/diffraction): as much as the lights layer holds, the pattern staying in the frame; most
    // of it stays in the light's own pixels, so the flare shows the light, not a hole.
    EXPECT_NEAR(lit, 1600.0, 1e-3);
    EXPECT_NEAR(diffraction, lit, 1e-4 * 1600.0);
    EXPECT_GT(spread, 0.0);
    EXPECT_GT(cores, spread);
    EXPECT_NE(e.spec.get_string_attribute("fourierflare:diffraction").find("physical, gain 1"), std::string::npos);
    EXPECT_TRUE(fs::exists(dir / "out.png"));
    const auto lights = nlohmann::json::parse(ff::test::readFile(dir / "lights.json"));
    ASSERT_EQ(lights["lights"].size(), 1u);
    // The light's 2 x 2 block centred on pixel corner (21, 13) of the data window, +3, +2 in the display window.
    EXPECT_NEAR(lights["lights"][0]["x"].get<double>(), 24.0, 1e-3);
    EXPECT_NEAR(lights["lights"][0]["y"].get<double>(), 15.0, 1e-3);
    EXPECT_NEAR(lights["lights"][0]["flux"][0].get<double>(), 4 * 400.0, 1e-6);
}

// By default the two layers a compositor grades apart; --layers chooses (written in one order),
// --half writes them as half floats: each value the float one rounded to half, or +-65504 beyond
// half's range (noted); a layer named twice or unknown is refused before anything is written.
TEST(CliSimulate, LayersAndHalf) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr", 20, 12, 400.0f);
    const std::string light = " --light 40.5,30.5,1e12,1e12,1e12"; // ghosts far beyond half's range
    ASSERT_EQ(run(simulate(dir / "plate.exr", dir / "default.exr", light), kEnv).code, 0);
    const Exr d = readExr(dir / "default.exr");
    EXPECT_EQ(d.spec.nchannels, 14); // R G B A Z + ghosts, diffraction, lights
    EXPECT_GE(d.channel("ghosts.R"), 0);
    EXPECT_GE(d.channel("diffraction.B"), 0);
    EXPECT_GE(d.channel("lights.G"), 0);
    EXPECT_LT(d.channel("flare.R"), 0);
    EXPECT_LT(d.channel("composite.R"), 0);
    EXPECT_EQ(d.spec.channelformat(d.channel("ghosts.G")), OIIO::TypeDesc::FLOAT);
    EXPECT_EQ(d.spec.get_string_attribute("fourierflare:channels").find("flare.R"), std::string::npos);

    const auto h = run(simulate(dir / "plate.exr", dir / "half.exr", "--half --layers composite,ghosts" + light), kEnv);
    ASSERT_EQ(h.code, 0) << h.err;
    EXPECT_NE(h.err.find("beyond half's range"), std::string::npos) << h.err;
    ASSERT_EQ(run(simulate(dir / "plate.exr", dir / "float.exr", "--layers all" + light), kEnv).code, 0);
    const Exr a = readExr(dir / "half.exr"), b = readExr(dir / "float.exr");
    EXPECT_EQ(a.spec.nchannels, 11);
    EXPECT_LT(a.channel("diffraction.R"), 0);
    std::size_t saturated = 0;
    for (const char* name : {"ghosts.R", "ghosts.B", "composite.G"}) {
        const int ca = a.channel(name), cb = b.channel(name);
        ASSERT_TRUE(ca >= 0 && cb >= 0) << name;
        EXPECT_EQ(a.spec.channelformat(ca), OIIO::TypeDesc::HALF);
        for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) {
            const float v = b.at(p, cb);
            const float expected =
                std::abs(v) > 65504.0f ? std::copysign(65504.0f, v) : static_cast<float>(static_cast<Imath::half>(v));
            saturated += std::abs(v) > 65504.0f;
            ASSERT_EQ(a.at(p, ca), expected) << name << " pixel " << p;
        }
    }
    EXPECT_GT(saturated, 0u);
    for (const std::string bad : {"ghosts,ghosts", "ghost", "", "all,flare"}) {
        const auto r = run(simulate(dir / "plate.exr", dir / "bad.exr", "--layers '" + bad + "'" + light), kEnv);
        EXPECT_EQ(r.code, 2) << bad;
        EXPECT_NE(r.err.find("--layers"), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "bad.exr"));
}

// The default (shaped) flare of a light found in a plate whose data window sits inside a larger
// display window is the traced flare (`render --mode traced`, every ghost ray-traced) of a light of
// the same flux at the same place of the display window, cropped to the data window.
// simulate's ghosts of one light on a plate whose data window sits inside a larger display window,
// against the traced flare of that light (render --mode traced) through `lens` on `sensor`.
void expectShapedFlareIsTheTracedFlare(const std::string& lens, const std::string& sensor) {
    ff::test::TempDir dir;
    constexpr int ox = 20, oy = 12, W = kW + ox + 4, H = kH + oy + 2;
    writePlate(dir / "plate.exr", 61, 17, 800.0f, ox, oy, 4, 2);
    const auto r = run("simulate --lens " + lens + " --plate '" + (dir / "plate.exr").string() + "' -o '" +
                           (dir / "out.exr").string() + "' --sensor-size " + sensor,
                       kEnv);
    ASSERT_EQ(r.code, 0) << r.err;
    // The light: the 2 x 2 block's centre, in the display window, with 4 x 800 per channel.
    const std::string light = std::to_string(61 + 1 + ox) + "," + std::to_string(17 + 1 + oy) + ",3200,3200,3200";
    const auto t =
        run("render " + lens + " --mode traced --light " + light + " --size " + std::to_string(W) + "x" +
                std::to_string(H) + " --sensor-size " + sensor + " -o '" + (dir / "traced.exr").string() + "'",
            kEnv);
    ASSERT_EQ(t.code, 0) << t.err;
    const Exr e = readExr(dir / "out.exr"), ref = readExr(dir / "traced.exr");
    ASSERT_EQ(ref.spec.width, W);
    const char* names[3] = {"ghosts.R", "ghosts.G", "ghosts.B"};
    for (int c = 0; c < 3; ++c) {
        const int ch = e.channel(names[c]);
        ASSERT_GE(ch, 0);
        double num = 0.0, den = 0.0, sum = 0.0, refSum = 0.0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const double a = e.at(static_cast<std::size_t>(y) * kW + x, ch);
                const double b = ref.at(static_cast<std::size_t>(y + oy) * W + x + ox, c);
                num += (a - b) * (a - b), den += b * b, sum += a, refSum += b;
            }
        ASSERT_GT(den, 0.0);
        EXPECT_LT(std::sqrt(num / den), 0.10) << lens << " " << names[c];
        EXPECT_NEAR(sum, refSum, 0.01 * refSum) << lens << " " << names[c];
    }
}

TEST(CliSimulate, ShapedFlareIsTheTracedFlareOfTheLightFound) {
    expectShapedFlareIsTheTracedFlare(kLens, "36x24");
}

// The bundled GRIN rod: its ghost through the graded element, cut by the rod's barrel inside it.
TEST(CliSimulate, AGradedLensFlaresThePlateAsItsTracedFlare) {
    expectShapedFlareIsTheTracedFlare("lenses/grin-rod-1.8mm-0.23-pitch.lens", "1x0.6667");
}

// A light beyond the lens's image circle (the Cooke triplet on a 200 mm wide sensor: the plate's
// corner is some 65 degrees off the axis, past any ray through the lens) has no direct image there, so
// no field to draw ghosts for: it gets no ghosts and a note, and the run succeeds.
TEST(CliSimulate, LightsBeyondTheImageCircleGetNoFlareAndANote) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr", 1, 1, 800.0f);
    const auto r = run(simulate(dir / "plate.exr", dir / "out.exr", "--sensor-size 200x133"), kEnv);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("1 of 1 lights lie where no field angle of the lens images a source"), std::string::npos)
        << r.err;
    const Exr e = readExr(dir / "out.exr");
    const int gG = e.channel("ghosts.G");
    ASSERT_GE(gG, 0);
    for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) ASSERT_EQ(e.at(p, gG), 0.0f);
}

// A light at the frame centre, Gaussian model: every ghost is centred, so the flare is
// point-symmetric about the centre, and its flux in the frame is the light's flux x each ghost's
// relative flux x the part of its Gaussian inside the frame — computed here from the ghost table at
// 0 degrees.
TEST(CliSimulate, CentredLightFluxAndSymmetryFollowTheTable) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr", kW / 2 - 1, kH / 2 - 1, 500.0f);
    const auto r =
        run(simulate(dir / "plate.exr", dir / "out.exr", "--sensor-size 36x24 --ghost-model gaussian"), kEnv);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto t = run("table " + kLens + " -o '" + (dir / "t.json").string() + "'", kEnv);
    ASSERT_EQ(t.code, 0) << t.err;
    const auto table = nlohmann::json::parse(ff::test::readFile(dir / "t.json"));
    const Exr e = readExr(dir / "out.exr");
    const double pitch = 36.0 / kW, halfW = 0.5 * kW * pitch, halfH = 0.5 * kH * pitch;
    const double lightFlux = 4 * 500.0;
    const std::vector<double> lambdas = table["wavelengths_nm"].get<std::vector<double>>();
    const char* names[3] = {"ghosts.R", "ghosts.G", "ghosts.B"};
    const double targets[3] = {650.0, 550.0, 450.0};
    for (int c = 0; c < 3; ++c) {
        std::size_t w = 0;
        for (std::size_t i = 1; i < lambdas.size(); ++i)
            if (std::abs(lambdas[i] - targets[c]) < std::abs(lambdas[w] - targets[c])) w = i;
        double expected = 0.0;
        for (const auto& g : table["ghosts"]) {
            const auto& wl = g["wavelengths"][w];
            const double flux = wl["relative_flux"][0].get<double>();
            if (flux <= 0.0) continue;
            // On the axis the radial direction is image y: sigma_t along x, sigma_r along y.
            const double sx = wl["gaussian"]["sigma_tangential_mm"][0].get<double>(),
                         sy = wl["gaussian"]["sigma_radial_mm"][0].get<double>();
            expected +=
                lightFlux * flux * std::erf(halfW / (std::sqrt(2.0) * sx)) * std::erf(halfH / (std::sqrt(2.0) * sy));
        }
        const int ch = e.channel(names[c]);
        ASSERT_GE(ch, 0);
        double sum = 0.0, peak = 0.0, asym = 0.0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const float v = e.at(static_cast<std::size_t>(y) * kW + x, ch),
                            m = e.at(static_cast<std::size_t>(kH - 1 - y) * kW + (kW - 1 - x), ch);
                sum += v;
                peak = std::max(peak, double(v));
                asym = std::max(asym, double(std::abs(v - m)));
            }
        EXPECT_NEAR(sum, expected, 3e-3 * expected) << names[c];
        EXPECT_LE(asym, 1e-3 * peak) << names[c];
    }
}

TEST(CliSimulate, OutputDoesNotDependOnTheThreadCount) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr", 70, 40, 300.0f);
    ASSERT_EQ(run("--threads 1 " + simulate(dir / "plate.exr", dir / "one.exr"), kEnv).code, 0);
    ASSERT_EQ(run("--threads 2 " + simulate(dir / "plate.exr", dir / "two.exr"), kEnv).code, 0);
    const Exr a = readExr(dir / "one.exr"), b = readExr(dir / "two.exr");
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)), 0);
}

TEST(CliSimulate, PlatesWithoutLightsAndTinyPlates) {
    ff::test::TempDir dir;
    writePlate(dir / "dark.exr", -1, -1, 0.0f);
    const auto r = run(simulate(dir / "dark.exr", dir / "out.exr", "--layers flare"), kEnv);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("0 lights above luminance 2.000"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("no flare, the output is the plate plus a zero flare layer"), std::string::npos) << r.err;
    const Exr e = readExr(dir / "out.exr");
    const int f = e.channel("flare.G");
    ASSERT_GE(f, 0);
    for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) ASSERT_EQ(e.at(p, f), 0.0f);
    // A 1 x 1 plate with a light in it.
    OIIO::ImageSpec spec(1, 1, 3, OIIO::TypeDesc::FLOAT);
    const float px[3] = {100.0f, 100.0f, 100.0f};
    auto out = OIIO::ImageOutput::create((dir / "one.exr").string());
    ASSERT_TRUE(out->open((dir / "one.exr").string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px) &&
                out->close());
    const auto one = run(simulate(dir / "one.exr", dir / "one-out.exr"), kEnv);
    EXPECT_EQ(one.code, 0) << one.err;
}

TEST(CliSimulate, RefusesBadInputsWithoutWritingAnything) {
    ff::test::TempDir dir;
    const fs::path out = dir / "out.exr";
    ff::test::writeFile(dir / "empty.exr", "");
    fs::create_directories(dir / "folder.exr");
    for (const fs::path& bad : {dir / "empty.exr", dir / "folder.exr", dir / "missing.exr"}) {
        const auto r = run(simulate(bad, out), kEnv);
        EXPECT_EQ(r.code, 2) << bad << "\n" << r.err;
        EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(out));
    }
    // A header claiming 16384 x 16384: refused before anything is allocated, unless allowed.
    writePlate(dir / "small.exr", -1, -1, 0.0f);
    ASSERT_TRUE(ff::test::writeHugeHeaderCopy(dir / "small.exr", dir / "huge.exr"));
    const auto huge = run(simulate(dir / "huge.exr", out), kEnv);
    EXPECT_EQ(huge.code, 2) << huge.err;
    EXPECT_NE(huge.err.find("16384x16384 = 268435456 pixels, above the limit of 67108864 (--max-pixels raises it)"),
              std::string::npos)
        << huge.err;
    EXPECT_FALSE(fs::exists(out));
    writePlate(dir / "plate.exr", 20, 12, 400.0f);
    EXPECT_EQ(run(simulate(dir / "plate.exr", dir / "plate.exr"), kEnv).code, 2); // output = input
    EXPECT_EQ(run(simulate(dir / "plate.exr", dir / "out.png"), kEnv).code, 2);   // not an EXR
    const auto folder = run(simulate(dir / "plate.exr", dir / "no" / "such" / "folder.exr"), kEnv);
    EXPECT_EQ(folder.code, 1) << folder.err;
    EXPECT_EQ(run(simulate(dir / "plate.exr", out, "--threshold max:2"), kEnv).code, 2);
    EXPECT_FALSE(fs::exists(out));
}

// --sensor is the sensor plane in simulate as everywhere; its old meaning, the sensor's size, still
// works for one release with a warning and gives the same image as --sensor-size.
TEST(CliSimulate, TheOldSensorSizeSpellingGivesTheSameImage) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr", 20, 12, 400.0f);
    const auto now = run(simulate(dir / "plate.exr", dir / "now.exr", "--sensor-size 30x20"), kEnv);
    const auto old = run(simulate(dir / "plate.exr", dir / "old.exr", "--sensor 30x20"), kEnv);
    ASSERT_EQ(now.code, 0) << now.err;
    ASSERT_EQ(old.code, 0) << old.err;
    EXPECT_NE(old.err.find("--sensor WxH is deprecated: use --sensor-size WxH"), std::string::npos) << old.err;
    const Exr a = readExr(dir / "now.exr"), b = readExr(dir / "old.exr");
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_TRUE(a.pixels == b.pixels);
    EXPECT_EQ(run(simulate(dir / "plate.exr", dir / "bad.exr", "--sensor 30x20 --sensor-size 30x20"), kEnv).code, 2);
    const auto plane = run(simulate(dir / "plate.exr", dir / "bad.exr", "--sensor focus"), kEnv);
    EXPECT_EQ(plane.code, 2);
    EXPECT_NE(plane.err.find("expected --sensor file or paraxial"), std::string::npos) << plane.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.exr"));
}

TEST(CliSimulate, SequencesRenderEveryFrame) {
    ff::test::TempDir dir;
    writePlate(dir / "shot.0007.exr", 20, 12, 400.0f);
    writePlate(dir / "shot.0008.exr", 60, 40, 400.0f);
    const auto r = run("simulate --lens " + kLens + " --plate '" + (dir / "shot.%04d.exr").string() +
                           "' --frames 7-8 -o '" + (dir / "out.%04d.exr").string() + "' --table-grid 8",
                       kEnv);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "out.0007.exr"));
    EXPECT_TRUE(fs::exists(dir / "out.0008.exr"));
}

TEST(CliSimulate, SharedPlatesRun) {
    const fs::path plates = ff::test::sharedDataDir() / "plates";
    if (!fs::exists(plates))
        GTEST_SKIP() << "shared plates not found at " << plates << " (they are not part of the repository)";
    ff::test::TempDir dir;
    for (const char* name : {"Desk.exr", "CandleGlass.exr", "BrightRingsNanInf.exr"}) {
        // Hundreds of lights at the default 32-pixel blocks: coarser blocks and meshes keep the run
        // to seconds (the cost of many lights is docs/performance.md's).
        const auto r = run(simulate(plates / name, dir / "out.exr", "--block 512 --table-grid 16"), kEnv);
        EXPECT_EQ(r.code, 0) << name << "\n" << r.err;
        EXPECT_TRUE(fs::exists(dir / "out.exr")) << name;
        if (std::string(name) == "CandleGlass.exr") {
            EXPECT_NE(r.err.find("have alpha 0 (premultiplied emission)"), std::string::npos) << r.err;
        }
        if (std::string(name) == "BrightRingsNanInf.exr") {
            EXPECT_NE(r.err.find("NaN or infinite"), std::string::npos) << r.err;
        }
        fs::remove(dir / "out.exr");
    }
}

// The checker process tells the guard the pixels' size as float once the header has passed its
// checks (image/plate.h): the guard's bound for reading them grows with it. A refused header: none.
TEST(CliSimulate, PlateCheckReportsThePixelsSizeOnceTheHeaderPassed) {
    ff::test::TempDir dir;
    writePlate(dir / "plate.exr", -1, -1, 0.0f);
    const std::string file = " -- '" + (dir / "plate.exr").string() + "'";
    const auto r = run("plate-check --max-pixels 1000000 --max-channels 64" + file);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.out, "header " + std::to_string(kW * kH * 5 * 4) + "\n"); // R, G, B, A, Z as 4-byte floats
    const auto refused = run("plate-check --max-pixels 10 --max-channels 64" + file);
    EXPECT_EQ(refused.code, 3);
    EXPECT_EQ(refused.out, "");
    EXPECT_NE(refused.err.find("above the limit of 10 "), std::string::npos) << refused.err;
}

namespace {

// simulate on each file of a folder: exit 2 within 10 s naming the file, nothing written. Returns the
// number of files.
int expectEachRefused(const fs::path& folder) {
    ff::test::TempDir dir;
    int files = 0;
    for (const auto& entry : fs::directory_iterator(folder)) {
        if (entry.path().filename() == "LICENSE") continue;
        ++files;
        const auto start = std::chrono::steady_clock::now();
        const auto r = run(simulate(entry.path(), dir / "out.exr"), kEnv);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_EQ(r.code, 2) << entry.path() << "\n" << r.err;
        EXPECT_LT(seconds, 10.0) << entry.path();
        EXPECT_NE(r.err.find("fourierflare: error: " + entry.path().string() + ": "), std::string::npos) << r.err;
        for (const auto& left : fs::directory_iterator(dir.path())) ADD_FAILURE() << "left behind: " << left.path();
    }
    return files;
}

} // namespace

TEST(CliSimulate, DamagedFilesFailCleanlyAndQuickly) {
    const fs::path damaged = ff::test::sharedDataDir() / "damaged";
    if (!fs::exists(damaged))
        GTEST_SKIP() << "damaged corpus not found at " << damaged << " (it is not part of the repository)";
    EXPECT_EQ(expectEachRefused(damaged), 40);
}

// What the plate fuzz target found in the image library (docs/reliability.md): a string attribute
// declaring 2 GB, a PNG chunk past the end, an EXR whose channel list aborts OpenImageIO. The
// guarded read contains each.
TEST(CliSimulate, ImageLibraryFaultsTheFuzzerFoundAreContained) {
    EXPECT_EQ(expectEachRefused(fs::path(FF_SOURCE_DIR) / "fuzz" / "findings" / "plate"), 5);
}

// --backend gl draws the flare with the compute shaders (llvmpipe where there is no GPU): the
// Fourier series of the fitted models, the polygons of the shaped one. The same EXR as --backend cpu
// within float32 rounding of the two evaluation orders.
TEST(CliSimulate, GlBackendMatchesTheCpuBackend) {
    for (const std::string model : {"gaussian", "shaped"}) {
        SCOPED_TRACE(model);
        ff::test::TempDir dir;
        writePlate(dir / "plate.exr", 30, 20, 800.0f);
        const std::string options = "--ghost-model " + model + " --fourier-n 32 --layers all";
        const auto gl = run(simulate(dir / "plate.exr", dir / "gl.exr", options + " --backend gl"), kEnv);
        if (gl.code == 1 && gl.err.find("no OpenGL 4.5 context") != std::string::npos) GTEST_SKIP() << gl.err;
        ASSERT_EQ(gl.code, 0) << gl.err;
        ASSERT_EQ(run(simulate(dir / "plate.exr", dir / "cpu.exr", options + " --backend cpu"), kEnv).code, 0);
        const Exr a = readExr(dir / "gl.exr"), b = readExr(dir / "cpu.exr");
        EXPECT_NE(a.spec.get_string_attribute("fourierflare:backend").find("gl: "), std::string::npos);
        double num = 0.0, den = 0.0;
        for (const char* name : {"flare.R", "flare.G", "flare.B"}) {
            const int ca = a.channel(name), cb = b.channel(name);
            ASSERT_TRUE(ca >= 0 && cb >= 0);
            for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) {
                const double d = double(a.at(p, ca)) - b.at(p, cb);
                num += d * d;
                den += double(b.at(p, cb)) * b.at(p, cb);
            }
        }
        EXPECT_GT(den, 0.0);
        EXPECT_LE(std::sqrt(num / den), 1e-5);
        for (const char* name : {"R", "G", "B", "A", "Z"}) { // the plate's channels: identical
            const int ca = a.channel(name), cb = b.channel(name);
            for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) ASSERT_EQ(a.at(p, ca), b.at(p, cb));
        }
        // The composite: the plate, plus the GL flare, less the lights the diffraction spread (to float
        // rounding: the plate gets the ghosts and the light the iris moves in one addition).
        for (const char* c : {"R", "G", "B"}) {
            const int plate = a.channel(c), flare = a.channel(std::string("flare.") + c),
                      lights = a.channel(std::string("lights.") + c), comp = a.channel(std::string("composite.") + c);
            for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) {
                const double v = double(a.at(p, plate)) + a.at(p, flare) - a.at(p, lights);
                ASSERT_NEAR(a.at(p, comp), v, 1e-6 * (a.at(p, plate) + a.at(p, flare) + a.at(p, lights)))
                    << c << " pixel " << p;
            }
        }
    }
}
