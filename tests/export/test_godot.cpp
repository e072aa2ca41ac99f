// The Godot export drawn by the engine itself: `export --format godot`, its project run headless by
// Godot 3 under Xvfb (Mesa's software GL), its frame against `render --mode fitted --preview` of the
// same light at the same exposure, and the ghosts it drew against the CLI's instances.

#include "cli/cli_runner.h"
#include "ghosts/instancing.h"
#include "ghosts/table_json.h"
#include "scene/scene.h"

#include <OpenImageIO/imagebuf.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using ff::test::run;
using ff::test::TempDir;

const std::string kEnv = std::string("FF_CACHE_DIR='") + FF_TEST_CACHE_DIR + "' ";
constexpr int kW = 640, kH = 360;

bool onPath(const char* program) {
    return std::system(("command -v " + std::string(program) + " >/dev/null 2>&1").c_str()) == 0;
}

// The PNG's values with the sRGB transfer undone: the tonemapped flux v / (1 + v) per channel.
std::vector<double> linearised(const fs::path& png) {
    OIIO::ImageBuf b(png.string());
    std::vector<float> px(static_cast<std::size_t>(kW) * kH * 3);
    EXPECT_TRUE(b.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << png;
    EXPECT_EQ(b.spec().width, kW);
    EXPECT_EQ(b.spec().height, kH);
    b.get_pixels(OIIO::ROI(0, kW, 0, kH, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT, px.data());
    std::vector<double> out(px.size());
    for (std::size_t i = 0; i < px.size(); ++i) {
        const double s = px[i];
        out[i] = s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
    }
    return out;
}

// The exposure the CLI chose for its preview, from "(exposure 24.65 EV)".
double exposureOf(const std::string& err) {
    const auto p = err.find("(exposure ");
    return p == std::string::npos ? std::nan("") : std::atof(err.c_str() + p + 10);
}

} // namespace

// For the double Gauss and the Nikon, three lights (near the centre, mid-field, near a corner): the
// engine's frame within 0.05 relative L2 of the CLI's preview (linearised), and every ghost the
// engine drew centred within 1 px of the CLI's instance of it, in the same order.
TEST(GodotExport, TheEngineDrawsTheFittedFlareOfTheCli) {
    if (!onPath("godot3") || !onPath("xvfb-run"))
        GTEST_SKIP() << "godot3 and xvfb-run are needed (Debian: godot3, xvfb; scripts/install-deps.sh)";
    for (const std::string lens : {"double-gauss-50mm-f2", "nikon-28-75mm-at-28mm"}) {
        SCOPED_TRACE(lens);
        TempDir dir;
        const fs::path project = dir / "project";
        const auto e = run("export lenses/" + lens + ".lens --format godot -o '" + project.string() + "'", kEnv);
        ASSERT_EQ(e.code, 0) << e.err;
        const ff::ghosts::GhostTable table = ff::ghosts::tableFromJson(
            ff::test::readFile(project / "addons/fourierflare/ghost_table.json"), "ghost_table.json");
        for (const auto& [x, y] :
             std::vector<std::pair<double, double>>{{330.5, 170.25}, {500.0, 100.0}, {40.0, 330.0}}) {
            SCOPED_TRACE(std::to_string(x) + "," + std::to_string(y));
            const std::string light = std::to_string(x) + "," + std::to_string(y);
            const fs::path cliPng = dir / "cli.png", enginePng = dir / "engine.png", drawn = dir / "ghosts.json";
            const auto r = run("render lenses/" + lens + ".lens --mode fitted --light " + light + " --size " +
                                   std::to_string(kW) + "x" + std::to_string(kH) + " --preview '" + cliPng.string() +
                                   "' -o '" + (dir / "cli.exr").string() + "'",
                               kEnv);
            ASSERT_EQ(r.code, 0) << r.err;
            const double ev = exposureOf(r.err);
            ASSERT_TRUE(std::isfinite(ev)) << r.err;
            char evText[32];
            std::snprintf(evText, sizeof evText, "%.17g", ev);
            // The engine's user data (logs) in the test's folder; its audio off.
            const std::string godot = "HOME='" + dir.path().string() + "' xvfb-run -a -s '-screen 0 800x600x24' " +
                                      "godot3 --audio-driver Dummy --path '" + project.string() + "' -- --light " +
                                      light + " --size " + std::to_string(kW) + "x" + std::to_string(kH) +
                                      " --exposure " + evText + " --output '" + enginePng.string() +
                                      "' --ghosts-out '" + drawn.string() + "' >'" + (dir / "godot.log").string() +
                                      "' 2>&1";
            ASSERT_EQ(std::system(godot.c_str()), 0) << ff::test::readFile(dir / "godot.log");

            const std::vector<double> a = linearised(enginePng), b = linearised(cliPng);
            double num = 0.0, den = 0.0;
            for (std::size_t i = 0; i < a.size(); ++i) num += (a[i] - b[i]) * (a[i] - b[i]), den += b[i] * b[i];
            ASSERT_GT(den, 0.0);
            EXPECT_LE(std::sqrt(num / den), 0.05);
            std::printf("%s at %s: relative L2 %.4f\n", lens.c_str(), light.c_str(), std::sqrt(num / den));

            const auto instances = ff::scene::fourierGhosts(
                ff::ghosts::instantiate(table, {{x, y, {1.0, 1.0, 1.0}}}, {kW, kH, table.sensorSizeMm.first / kW}));
            const auto engine = nlohmann::json::parse(ff::test::readFile(drawn));
            ASSERT_EQ(engine.size(), instances.size());
            double worst = 0.0;
            for (std::size_t k = 0; k < instances.size(); ++k) {
                EXPECT_NEAR(engine[k][0].get<double>(), instances[k].x, 1.0) << "ghost " << k;
                EXPECT_NEAR(engine[k][1].get<double>(), instances[k].y, 1.0) << "ghost " << k;
                worst = std::max({worst, std::abs(engine[k][0].get<double>() - instances[k].x),
                                  std::abs(engine[k][1].get<double>() - instances[k].y)});
            }
            std::printf("  %zu ghosts, centres at most %.2g px from the CLI's\n", instances.size(), worst);
        }
    }
}
