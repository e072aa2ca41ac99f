// `fourierflare ghosts` and `fourierflare render` as a user runs them.

#include "core/file_io.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <numeric>

#include "cli_runner.h"
#include "test_support.h"

using ff::test::run;

TEST(CliGhosts, ReportsAll45GhostsOfTheDoubleGauss) {
    const auto r = run("ghosts lenses/double-gauss-50mm-f2.lens --angle 10 --wavelength 550 --coating none "
                       "--sampling paraxial-grid --grid 64 --sensor paraxial --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["ghost_count"], 45);
    const auto& w = j["wavelengths"][0];
    ASSERT_EQ(w["ghosts"].size(), 45u);
    EXPECT_GT(w["direct"]["centroid_mm"][1].get<double>(), 0.0);
    const double total = w["total_ghost_relative_energy"].get<double>();
    EXPECT_GT(total, 0.015); // uncoated: 1.5-6 % (optics reference)
    EXPECT_LT(total, 0.06);
    double previous = 1.0;
    for (const auto& g : w["ghosts"]) {
        const double e = g["relative_energy"].get<double>();
        EXPECT_LE(e, previous);
        previous = e;
        EXPECT_GT(g["surfaces"][0].get<int>(), g["surfaces"][1].get<int>());
    }
}

// The GRIN rod on the axis, uncoated: its one ghost reflects off the back face, then the front face,
// at normal incidence where the local index is between n(0.9 mm) = 1.608 - 0.0923965 x 0.81 and
// n0 = 1.608, so it carries between R(1.5332)^2 = 1.96e-3 and R(1.608)^2 = 2.95e-3 of the direct
// image (R = ((n - 1) / (n + 1))^2; on the axis no ray leaves the rod: a parabolic medium keeps a
// parallel ray's height within its entry height).
TEST(CliGhosts, TheGrinRodsGhostCarriesItsFacesReflectances) {
    const auto r = run("ghosts lenses/grin-rod-1.8mm-0.23-pitch.lens --angle 0 --wavelength 550 --coating none --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["ghost_count"], 1);
    const auto R = [](double n) { return (n - 1) * (n - 1) / ((n + 1) * (n + 1)); };
    const double e = j["wavelengths"][0]["ghosts"][0]["relative_energy"].get<double>();
    EXPECT_GT(e, R(1.608 - 0.0923965 * 0.81) * R(1.608 - 0.0923965 * 0.81));
    EXPECT_LT(e, R(1.608) * R(1.608));
}

TEST(CliGhosts, TextReportAndTopK) {
    const auto r = run("ghosts lenses/cooke-triplet-50mm-f5.lens --angle 5 --top 3");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("6 reflecting interfaces -> 15 two-bounce ghosts, the 3 strongest shown"), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("total ghost energy / direct energy"), std::string::npos);
    EXPECT_EQ(run("ghosts lenses/cooke-triplet-50mm-f5.lens").code, 2); // --angle is required
    EXPECT_EQ(run("ghosts lenses/cooke-triplet-50mm-f5.lens --angle 5 --coating x").code, 2);
}

TEST(CliRender, WritesAFluxExrWithProvenanceAndAPreview) {
    ff::test::TempDir dir;
    const std::string exr = (dir / "flare.exr").string(), png = (dir / "flare.png").string();
    const auto r = run("render lenses/double-gauss-50mm-f2.lens --angle 12,30 --size 160x90 --grid 16 -o '" + exr +
                       "' --preview '" + png + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    auto in = OIIO::ImageInput::open(exr);
    ASSERT_TRUE(in);
    const OIIO::ImageSpec& spec = in->spec();
    EXPECT_EQ(spec.width, 160);
    EXPECT_EQ(spec.height, 90);
    ASSERT_EQ(spec.nchannels, 3);
    EXPECT_EQ(spec.channelnames[0], "R");
    EXPECT_EQ(spec.get_string_attribute("compression"), "zip");
    EXPECT_EQ(spec.get_string_attribute("fourierflare:lensHash").size(), 16u);
    EXPECT_NE(spec.get_string_attribute("fourierflare:commandLine").find("--angle 12,30"), std::string::npos);
    std::vector<float> px(160 * 90 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data()));
    in->close();
    double sum = 0.0;
    for (float v : px) {
        ASSERT_TRUE(std::isfinite(v));
        ASSERT_GE(v, 0.0f);
        sum += v;
    }
    EXPECT_GT(sum, 0.0);
    EXPECT_LT(sum, 3.0); // ghosts carry a small fraction of the source's flux in each channel
    EXPECT_TRUE(std::filesystem::exists(png));
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 2); // no temporaries left
}

TEST(CliRender, LightPositionAndErrors) {
    ff::test::TempDir dir;
    const std::string exr = (dir / "l.exr").string();
    const auto centre =
        run("render lenses/cooke-triplet-50mm-f5.lens --light 40,10 --size 80x60 --grid 8 -o '" + exr + "'");
    EXPECT_EQ(centre.code, 0) << centre.err;
    EXPECT_NE(centre.err.find("traced 15 ghosts"), std::string::npos) << centre.err;
    EXPECT_EQ(run("render lenses/cooke-triplet-50mm-f5.lens --size 80x60 -o '" + exr + "'").code, 2); // no source
    EXPECT_EQ(run("render lenses/cooke-triplet-50mm-f5.lens --angle 5 --size 80 -o '" + exr + "'").code, 2);
    EXPECT_EQ(
        run("render lenses/cooke-triplet-50mm-f5.lens --angle 5 --size 80x60 -o lenses/cooke-triplet-50mm-f5.lens")
            .code,
        2);
    // A light far outside the Cooke triplet's field (its chief ray cannot get there).
    const auto far = run("render lenses/cooke-triplet-50mm-f5.lens --light 100000,10 --size 80x60 -o '" + exr + "'");
    EXPECT_EQ(far.code, 2) << far.err;
    EXPECT_NE(far.err.find("no field angle images a source"), std::string::npos) << far.err;
}

// render --angle draws the shaped ghosts of one source by its field, as the traced mode does: the same
// lens and field, two independent renderers (the traced one refines the pupil per frame, the shaped
// one interpolates the table's meshes between its angles), agree per pixel within the shaped
// ghosts' measured error (docs/ghost-table.md: 0.002-0.004 for the Cooke triplet at 960 x 540).
TEST(CliRender, ShapedByFieldAngleMatchesTheTracedFlare) {
    ff::test::TempDir dir;
    const std::string env = "FF_CACHE_DIR='" + (dir / "cache").string() + "' ";
    const std::string common = "render lenses/cooke-triplet-50mm-f5.lens --angle 9.3,40 --size 320x180 ";
    auto image = [&](const std::string& mode) {
        const std::string exr = (dir / (mode + ".exr")).string();
        const auto r = run(common + "--mode " + mode + " -o '" + exr + "'", env);
        EXPECT_EQ(r.code, 0) << r.err;
        std::vector<float> px(320 * 180 * 3, 0.0f);
        auto in = OIIO::ImageInput::open(exr);
        if (in) in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data());
        return px;
    };
    const std::vector<float> traced = image("traced"), shaped = image("shaped");
    for (int c = 0; c < 3; ++c) {
        double d = 0.0, n = 0.0;
        for (std::size_t p = c; p < traced.size(); p += 3)
            d += std::pow(double(shaped[p]) - traced[p], 2), n += std::pow(double(traced[p]), 2);
        ASSERT_GT(n, 0.0);
        EXPECT_LT(std::sqrt(d / n), 0.02) << "channel " << c;
    }
    // Beyond the table's field (the sensor's half-diagonal plus 5 %, 24.5 deg here) the shaped ghosts are not
    // known: an error naming the option that extends it, no image.
    const std::string beyond = (dir / "beyond.exr").string();
    const auto far = run(
        common.substr(0, common.find("--angle")) + "--angle 40 --size 64x36 --mode shaped -o '" + beyond + "'", env);
    EXPECT_EQ(far.code, 2) << far.err;
    EXPECT_NE(far.err.find("--max-angle"), std::string::npos) << far.err;
    EXPECT_FALSE(std::filesystem::exists(beyond));
}

TEST(CliTable, BuildsCachesAndExports) {
    ff::test::TempDir dir;
    const std::string env = "FF_CACHE_DIR='" + (dir / "cache").string() + "' ";
    const std::string table = (dir / "t.json").string(), asset = (dir / "cooke.asset").string();
    const auto built =
        run("table lenses/cooke-triplet-50mm-f5.lens --table-grid 8 --max-angle 10 -o '" + table + "'", env);
    ASSERT_EQ(built.code, 0) << built.err;
    EXPECT_NE(built.err.find("built table: 15 ghosts x 3 wavelengths at 25 field angles"), std::string::npos)
        << built.err;
    EXPECT_NE(built.err.find("fit error (relative L2)"), std::string::npos) << built.err;
    const auto j = nlohmann::json::parse(ff::test::readFile(table));
    EXPECT_EQ(j["schema"], "fourierflare.ghost-table");
    EXPECT_EQ(j["ghosts"].size(), 15u);
    const auto exported =
        run("export lenses/cooke-triplet-50mm-f5.lens --format unity --table-grid 8 --max-angle 10 --top 5 -o '" +
                asset + "'",
            env);
    ASSERT_EQ(exported.code, 0) << exported.err;
    EXPECT_NE(exported.err.find("table from the cache"), std::string::npos)
        << exported.err; // same settings as the table command
    const std::string text = ff::test::readFile(asset);
    EXPECT_EQ(text.rfind("%YAML 1.1", 0), 0u);
    EXPECT_NE(text.find("m_Name: cooke"), std::string::npos);
    EXPECT_EQ(run("export lenses/cooke-triplet-50mm-f5.lens --format gif -o '" + asset + "'", env).code, 2);
    EXPECT_TRUE(std::filesystem::is_directory(dir / "cache")); // the table went to the given cache

    // godot: a project folder, the whole table in it; exported again over itself, replaced; a folder
    // of other files is refused before any work, and left as it was.
    const std::string godot = "export lenses/cooke-triplet-50mm-f5.lens --format godot --table-grid 8 --max-angle 10 ";
    const auto project = dir / "project";
    for (int i = 0; i < 2; ++i) {
        const auto g = run(godot + "-o '" + project.string() + "'", env);
        ASSERT_EQ(g.code, 0) << g.err;
    }
    for (const char* f : {"project.godot", "flare_frame.tscn", "flare_frame.gd", "addons/fourierflare/lens_flare.gd",
                          "addons/fourierflare/lens_flare.shader"})
        EXPECT_GT(std::filesystem::file_size(project / f), 0u) << f;
    EXPECT_EQ(nlohmann::json::parse(ff::test::readFile(project / "addons/fourierflare/ghost_table.json")),
              nlohmann::json::parse(ff::test::readFile(table)));
    std::filesystem::create_directory(dir / "theirs");
    ff::writeFileAtomic(dir / "theirs/notes.txt", "mine");
    const auto refused = run(godot + "-o '" + (dir / "theirs").string() + "'", env);
    EXPECT_EQ(refused.code, 2);
    EXPECT_NE(refused.err.find("not an empty folder or an earlier Godot export"), std::string::npos) << refused.err;
    EXPECT_EQ(ff::test::readFile(dir / "theirs/notes.txt"), "mine");
    EXPECT_FALSE(std::filesystem::exists(dir / "theirs/project.godot"));
}
