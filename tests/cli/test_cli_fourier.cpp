// `fourierflare render --mode fitted|fourier`, explicit ghost lists and `fourierflare compare`.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "cli_runner.h"
#include "test_support.h"

using ff::test::run;

namespace {

void write(const std::filesystem::path& p, const std::string& text) {
    std::ofstream(p) << text;
}

// Parses "probe X,Y: R G B" lines.
std::vector<std::array<double, 3>> probes(const std::string& out) {
    std::vector<std::array<double, 3>> v;
    std::size_t pos = 0;
    while ((pos = out.find("probe ", pos)) != std::string::npos) {
        const std::size_t colon = out.find(':', pos);
        std::array<double, 3> rgb{};
        if (std::sscanf(out.c_str() + colon + 1, "%lf %lf %lf", &rgb[0], &rgb[1], &rgb[2]) == 3) v.push_back(rgb);
        pos = colon;
    }
    return v;
}

} // namespace

TEST(CliFourier, GhostListRendersTheAnalyticValueInBothModes) {
    ff::test::TempDir dir;
    // One Gaussian with its centre on a pixel corner: pixel (32, 20) holds flux x P(0<X<1) x P(0<Y<1).
    write(
        dir / "g.json",
        R"({"ghosts": [{"x": 32, "y": 20, "profile": "gaussian", "widthX": 5, "widthY": [3, 4, 5], "flux": [1, 2, 3]}]})");
    auto mass = [](double s) { return 0.5 * std::erf(1.0 / (s * std::numbers::sqrt2)); };
    for (const char* mode : {"fitted", "fourier"}) {
        const auto r = run(std::string("render --ghosts '") + (dir / "g.json").string() + "' --size 64x40 --mode " +
                           mode + " --probe 32,20 --probe 2,2 -o '" + (dir / "g.exr").string() + "'");
        ASSERT_EQ(r.code, 0) << r.err;
        const auto p = probes(r.out);
        ASSERT_EQ(p.size(), 2u) << r.out;
        const double widthsY[3] = {3, 4, 5};
        for (int c = 0; c < 3; ++c) {
            const double expected = (c + 1) * mass(5.0) * mass(widthsY[c]);
            EXPECT_NEAR(p[0][c], expected, 1e-3 * expected) << mode;
            EXPECT_LT(p[1][c], 1e-3 * expected) << mode;
        }
    }
}

TEST(CliFourier, GhostListOnTheGlBackendGivesTheAnalyticValue) {
    ff::test::TempDir dir;
    // A small ghost (drawn directly) and a large one (through the series), both with their centre on
    // a pixel corner, far enough apart that each probe sees one.
    write(dir / "g.json", R"({"ghosts": [{"x": 20, "y": 20, "widthX": 1.5, "widthY": 2, "flux": [1, 2, 3]},
                                         {"x": 100, "y": 40, "widthX": 12, "widthY": 10, "flux": 50}]})");
    auto mass = [](double s) { return 0.5 * std::erf(1.0 / (s * std::numbers::sqrt2)); };
    const auto r = run("render --ghosts '" + (dir / "g.json").string() +
                       "' --size 160x80 --mode fourier --backend gl --fourier-n 24 --probe 20,20 --probe 100,40 -o '" +
                       (dir / "g.exr").string() + "'");
    if (r.code == 1 && r.err.find("no OpenGL 4.5 context") != std::string::npos) GTEST_SKIP() << r.err;
    ASSERT_EQ(r.code, 0) << r.err;
    const auto p = probes(r.out);
    ASSERT_EQ(p.size(), 2u) << r.out;
    for (int c = 0; c < 3; ++c) {
        const double small = (c + 1) * mass(1.5) * mass(2.0), large = 50.0 * mass(12.0) * mass(10.0);
        EXPECT_NEAR(p[0][c], small, 1e-3 * small);
        EXPECT_NEAR(p[1][c], large, 1e-3 * large);
    }
}

TEST(CliFourier, GhostListErrorsNameTheEntry) {
    ff::test::TempDir dir;
    write(dir / "bad.json", R"({"ghosts": [{"x": 1, "y": 2, "widthX": 3, "widthY": -1, "flux": 1}]})");
    const auto r = run("render --ghosts '" + (dir / "bad.json").string() + "' --size 16x16 --mode fourier -o '" +
                       (dir / "o.exr").string() + "'");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("ghosts[0].widthY: values must be finite and positive"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "o.exr"));
    write(dir / "syntax.json", "{\"ghosts\": [\n  {\"x\": 1,, }]}");
    const auto s = run("render --ghosts '" + (dir / "syntax.json").string() + "' --size 16x16 --mode fitted -o '" +
                       (dir / "o.exr").string() + "'");
    EXPECT_EQ(s.code, 2);
    EXPECT_NE(s.err.find("syntax.json:2:"), std::string::npos) << s.err;
    const auto traced =
        run("render --ghosts '" + (dir / "bad.json").string() + "' --size 16x16 -o '" + (dir / "o.exr").string() + "'");
    EXPECT_EQ(traced.code, 2);
}

TEST(CliFourier, FittedAndFourierOfALensAgreeAndKeepFlux) {
    ff::test::TempDir dir;
    const std::string env = "FF_CACHE_DIR='" + (dir / "cache").string() + "' ";
    const std::string common =
        "render lenses/cooke-triplet-50mm-f5.lens --light 150,40 --light 60,80,2,1,0.5 --size 192x108 --table-grid 8 ";
    const auto fitted = run(common + "--mode fitted --probe 96,54 -o '" + (dir / "a.exr").string() + "'", env);
    ASSERT_EQ(fitted.code, 0) << fitted.err;
    const auto four = run("-v " + common + "--mode fourier --probe 96,54 -o '" + (dir / "b.exr").string() + "'", env);
    ASSERT_EQ(four.code, 0) << four.err;
    EXPECT_NE(four.err.find("fourier: seconds: plan"), std::string::npos) << four.err; // --verbose
    const auto a = probes(fitted.out), b = probes(four.out);
    ASSERT_EQ(a.size(), 1u);
    ASSERT_EQ(b.size(), 1u);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(b[0][c], a[0][c], 1e-2 * a[0][c] + 1e-12);
    // Both print the frame's flux; the Fourier one keeps the fitted one's to the budget.
    auto flux = [](const std::string& err) {
        std::array<double, 3> f{};
        const std::size_t p = err.find("flux in the frame (R, G, B): ");
        if (p != std::string::npos) std::sscanf(err.c_str() + p + 29, "%lf %lf %lf", &f[0], &f[1], &f[2]);
        return f;
    };
    const auto fa = flux(fitted.err), fb = flux(four.err);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(fa[c], 0.0);
        EXPECT_NEAR(fb[c], fa[c], 1e-3 * fa[c]);
    }
    EXPECT_EQ(run(common + "--mode fourier --angle 5 -o '" + (dir / "c.exr").string() + "'", env).code,
              2); // --angle: traced or shaped only
}

namespace {

// The flux `render` prints for the frame (R, G, B): the light's, less what the round iris's Airy
// pattern throws beyond the square frame of half-side a pixels around it. Its mean far field is
// beta / (pi^3 r^3) of the flux per pixel (beta = lambda N / pitch), so beyond the square
// beta / pi^3 x Int dtheta / r_square(theta) = 4 sqrt 2 beta / (pi^3 a): at f/5 on pixels of 20 um,
// lambda 600, 550, 450 nm for R, G, B; within 30 % of it.
void expectFluxInFrame(const std::string& err, std::array<double, 3> light) {
    std::array<double, 3> f{};
    const std::size_t p = err.find("flux in the frame (R, G, B): ");
    ASSERT_NE(p, std::string::npos) << err;
    std::sscanf(err.c_str() + p + 29, "%lf %lf %lf", &f[0], &f[1], &f[2]);
    const double a = 64.0, N = 5.0, pitch = 0.02, lambda[3] = {600e-6, 550e-6, 450e-6};
    for (std::size_t c = 0; c < 3; ++c) {
        const double beyond = 4.0 * std::sqrt(2.0) * lambda[c] * N / pitch / (std::pow(std::numbers::pi, 3) * a);
        EXPECT_NEAR(f[c], light[c] * (1.0 - beyond), 0.3 * beyond * light[c] + 1e-5 * light[c]) << c;
    }
}

} // namespace

// render --mode diffraction: the light's flux spread by the lens's PSF, all of it in the frame but its
// far field's share beyond it (printed to 5 digits), and symmetric through the light's pixel (the
// pattern of a real pupil is).
TEST(CliRender, DiffractionModeSpreadsTheLightsFlux) {
    ff::test::TempDir dir;
    // Pixels of 20 um: the PSF's near field reaches 39 pixels, inside the frame.
    const auto r = run("render lenses/cooke-triplet-50mm-f5.lens --mode diffraction --light 64.5,64.5,2,1,0.5 "
                       "--size 129x129 --sensor-size 2.58x2.58 --probe 64,64 --probe 65,64 --probe 63,64 --probe 68,61 "
                       "--probe 60,67 -o '" +
                       (dir / "d.exr").string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    expectFluxInFrame(r.err, {2.0, 1.0, 0.5});
    const auto v = probes(r.out);
    ASSERT_EQ(v.size(), 5u);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(v[0][c], v[1][c]);                   // the core at the light's pixel
        EXPECT_NEAR(v[1][c], v[2][c], 1e-5 * v[0][c]); // symmetric through it
        EXPECT_NEAR(v[3][c], v[4][c], 1e-5 * v[0][c]);
        EXPECT_GT(v[3][c], 0.0);
    }
    EXPECT_NE(r.err.find("working f/"), std::string::npos) << r.err;
}

// render --mode diffraction with the light outside the frame: its diffraction reaches in, as in a
// frame larger by 40 pixels on the left that holds the light (pixels of the same 20 um: a sensor as
// much wider), whose probes are the same pixels of the scene.
TEST(CliRender, DiffractionReachesInFromALightOutsideTheFrame) {
    ff::test::TempDir dir;
    const std::string common = "render lenses/cooke-triplet-50mm-f5.lens --mode diffraction ";
    const auto window = run(common +
                            "--light=-20.5,30.5,2,1,0.5 --size 96x64 --sensor-size 1.92x1.28 --probe 0,30 "
                            "--probe 10,5 --probe 95,63 -o '" +
                            (dir / "w.exr").string() + "'");
    const auto large = run(common +
                           "--light=19.5,30.5,2,1,0.5 --size 136x64 --sensor-size 2.72x1.28 --probe 40,30 "
                           "--probe 50,5 --probe 135,63 -o '" +
                           (dir / "l.exr").string() + "'");
    ASSERT_EQ(window.code, 0) << window.err;
    ASSERT_EQ(large.code, 0) << large.err;
    const auto a = probes(window.out), b = probes(large.out);
    ASSERT_EQ(a.size(), 3u);
    ASSERT_EQ(b.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t c = 0; c < 3; ++c) {
            EXPECT_GT(a[i][c], 0.0) << i << " " << c;
            EXPECT_NEAR(a[i][c], b[i][c], 1e-4 * b[i][c]) << i << " " << c;
        }
}

// render --mode diffraction --diffraction traced: the light on the axis, where the lens's wavefront
// is symmetric about it, keeps its flux in the frame and its pattern symmetric through its pixel;
// the lens's own aberrations (spherical, colour) change the pattern from the aberration-free one.
TEST(CliRender, DiffractionTracedKeepsTheFluxAndTheAxialSymmetry) {
    ff::test::TempDir dir;
    const std::string common = "render lenses/cooke-triplet-50mm-f5.lens --mode diffraction --light 64.5,64.5,2,1,0.5 "
                               "--size 129x129 --sensor-size 2.58x2.58 --probe 64,64 --probe 65,64 --probe 63,64 "
                               "--probe 64,67 --probe 64,61 -o '" +
                               (dir / "d.exr").string() + "' ";
    const auto ideal = run(common), r = run(common + "--diffraction traced");
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_EQ(ideal.code, 0) << ideal.err;
    EXPECT_NE(r.err.find("the lens's traced wavefront"), std::string::npos) << r.err;
    expectFluxInFrame(r.err, {2.0, 1.0, 0.5});
    const auto v = probes(r.out), w = probes(ideal.out);
    ASSERT_EQ(v.size(), 5u);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(v[1][c], v[2][c], 1e-4 * v[0][c]); // symmetric through the light's pixel
        EXPECT_NEAR(v[3][c], v[4][c], 1e-4 * v[0][c]);
        EXPECT_GT(std::abs(v[0][c] - w[0][c]), 1e-3 * w[0][c]); // not the aberration-free core
    }
    EXPECT_EQ(run(common + "--diffraction off").code, 2);
}

TEST(CliCompare, WritesTheReport) {
    ff::test::TempDir dir;
    const std::string env = "FF_CACHE_DIR='" + (dir / "cache").string() + "' ";
    const auto out = dir / "cmp";
    const auto r = run("compare lenses/cooke-triplet-50mm-f5.lens --light 150,40 --size 192x108 --grid 8 --table-grid "
                       "8 --fourier-n-sweep 8,16,32 "
                       "--diffraction traced -o '" +
                           out.string() + "'",
                       env);
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* f : {"report.md", "report.json", "error-vs-n.svg", "traced.exr", "traced.png",
                          "fitted-gaussian.exr", "fourier-cos2.png", "diff-fourier-gaussian-vs-traced.png",
                          "shaped.exr", "shaped-hybrid.exr", "shaped-hybrid.png", "diffraction-physical.exr",
                          "diffraction-traced.png", "diff-diffraction-traced-vs-physical.png"})
        EXPECT_TRUE(std::filesystem::exists(out / f)) << f;
    const auto j = nlohmann::json::parse(ff::test::readFile(out / "report.json"));
    for (const char* p : {"gaussian", "cos2"}) {
        const auto& prof = j["profiles"][p];
        ASSERT_EQ(prof["errorVsN"].size(), 3u);
        // More terms never make the truncation error larger.
        EXPECT_LE(prof["errorVsN"][2]["vsFitted"]["relativeL2"].get<double>(),
                  prof["errorVsN"][0]["vsFitted"]["relativeL2"].get<double>() + 1e-9);
        EXPECT_LE(prof["fourierVsFitted"]["relativeL2"].get<double>(), 1e-3); // the hybrid keeps the budget
        EXPECT_NEAR(prof["fourierVsFitted"]["fluxRatio"].get<double>(), 1.0, 1e-3);
    }
    // The shaped hybrid keeps its estimate against every instance drawn directly (over all channels
    // the relative L2 is at most the largest channel's).
    EXPECT_LE(j["shapedHybrid"]["vsShaped"]["relativeL2"].get<double>(),
              j["shapedHybrid"]["estimatedError"].get<double>() + 1e-7);
    EXPECT_NEAR(j["shapedHybrid"]["vsShaped"]["fluxRatio"].get<double>(), 1.0, 1e-3);
    EXPECT_NE(ff::test::readFile(out / "report.md").find("| comparison | relative L2 |"), std::string::npos);
    // The reference states its own error (against twice the refinement), and it is far below the
    // profile model's, or the comparison would measure the reference.
    EXPECT_NE(ff::test::readFile(out / "report.md").find("(the reference's own error)"), std::string::npos);
    const double own = j["reference"]["relativeL2"].get<double>();
    EXPECT_GE(own, 0.0);
    EXPECT_LT(own, 0.2 * j["profiles"]["gaussian"]["fittedVsTraced"]["relativeL2"].get<double>());
    // --diffraction traced: both PSFs keep the light's flux in the frame (the light is 40 px from its
    // edges, the kernels reach a few pixels) and differ by what the lens's aberrations change.
    for (const char* mode : {"physical", "traced"})
        EXPECT_NEAR(j["diffraction"][mode]["fluxInFrame"].get<double>(), 1.0, 1e-4) << mode;
    EXPECT_GT(j["diffraction"]["tracedVsPhysical"]["relativeL2"].get<double>(), 0.0);
    EXPECT_NE(ff::test::readFile(out / "report.md").find("## Diffraction"), std::string::npos);
    EXPECT_EQ(run("compare lenses/cooke-triplet-50mm-f5.lens --size 64x64 -o '" + out.string() + "'", env).code,
              2); // no lights
}
