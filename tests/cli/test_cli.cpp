// The fourierflare executable as a user meets it: output, error format, exit codes.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>

#include "cli_runner.h"
#include "test_support.h"

namespace {

using ff::test::run;
using ff::test::RunResult;

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

} // namespace

TEST(Cli, LensInfoPrintsTheFirstOrderDataOfTheDoubleGauss) {
    const RunResult r = run("lens info lenses/double-gauss-50mm-f2.lens");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "effective focal length    50.358 mm")) << r.out;
    EXPECT_TRUE(contains(r.out, "back focal distance       36.106 mm")) << r.out;
    EXPECT_TRUE(contains(r.out, "f/2.03")) << r.out;
    EXPECT_TRUE(contains(r.out, "two-bounce ghosts         45")) << r.out;
    EXPECT_TRUE(contains(r.out, "US 2,673,491")) << r.out;
}

TEST(Cli, LensInfoJsonIsMachineReadable) {
    const RunResult r = run("lens info lenses/zoom-70-200mm-f2.8.lens --json --wavelength 550");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["wavelength_nm"].get<double>(), 550.0);
    ASSERT_EQ(j["first_order"].size(), 3u); // every zoom position
    EXPECT_EQ(j["first_order"][1]["label"], "135");
    EXPECT_EQ(j["surfaces"].size(), 34u);
    EXPECT_EQ(j["first_order"][0]["two_bounce_ghosts"].get<int>(), 528);
}

// An anamorphic lens: both sections' first-order data and the squeeze (the numbers themselves are
// checked against the design in tests/optics/test_anamorphic.cpp); a rotationally symmetric lens
// reports as before, without them; the traced flare takes the lens, the other modes refuse it with
// the reason.
TEST(Cli, LensInfoReportsBothSectionsOfAnAnamorphic) {
    const std::string lens = "lenses/anamorphic-2x-double-gauss-50mm.lens";
    const RunResult text = run("lens info " + lens);
    ASSERT_EQ(text.code, 0) << text.err;
    EXPECT_TRUE(contains(text.out, "the y-z section (anamorphic lens")) << text.out;
    EXPECT_TRUE(contains(text.out, "squeeze                   2.0000")) << text.out;
    const RunResult r = run("lens info " + lens + " --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out)["first_order"][0];
    EXPECT_NEAR(j["squeeze"].get<double>(), j["efl_mm"].get<double>() / j["section_x"]["efl_mm"].get<double>(), 1e-12);
    EXPECT_EQ(nlohmann::json::parse(r.out)["surfaces"][1]["radius_y_mm"], nullptr); // flat in y
    const auto round = nlohmann::json::parse(run("lens info lenses/double-gauss-50mm-f2.lens --json").out);
    EXPECT_FALSE(round["first_order"][0].contains("section_x"));
    EXPECT_FALSE(round["first_order"][0].contains("squeeze"));
    ff::test::TempDir dir;
    const std::string fitted = (dir / "fitted.exr").string(), traced = (dir / "traced.exr").string();
    const RunResult refused = run("render " + lens + " --mode fitted --light 10,10 -o '" + fitted + "'");
    EXPECT_EQ(refused.code, 2);
    EXPECT_TRUE(contains(refused.err, "the fitted ghosts (their table, fits and exports) and the traced wavefront need "
                                      "a rotationally symmetric lens"))
        << refused.err;
    EXPECT_FALSE(std::filesystem::exists(fitted));
    // The traced flare takes it (coarse: the anamorphic traces are checked in tests/trace).
    // Its EXR in sensor pixels with the squeeze as the pixel aspect ratio; the preview desqueezed when
    // asked: 160 x 90 becomes 320 x 90.
    const std::string preview = (dir / "traced.png").string();
    const RunResult ok = run("render " + lens + " --mode traced --light 100,30 --size 160x90 --grid 4 -o '" + traced +
                             "' --preview '" + preview + "' --desqueeze");
    EXPECT_EQ(ok.code, 0) << ok.err;
    auto exr = OIIO::ImageInput::open(traced);
    ASSERT_TRUE(exr);
    EXPECT_EQ(exr->spec().width, 160);
    EXPECT_NEAR(exr->spec().get_float_attribute("PixelAspectRatio", 1.0f), 2.0f, 1e-4f);
    auto png = OIIO::ImageInput::open(preview);
    ASSERT_TRUE(png);
    EXPECT_EQ(png->spec().width, 320);
    EXPECT_EQ(png->spec().height, 90);
    // So does the aberration-free diffraction (a front attachment leaves the prime's PSF); the traced
    // wavefront does not.
    const std::string diffraction = (dir / "diffraction.exr").string();
    EXPECT_EQ(run("render " + lens + " --mode diffraction --light 80,45 --size 160x90 -o '" + diffraction + "'").code,
              0);
    EXPECT_EQ(run("render " + lens + " --mode diffraction --diffraction traced --light 80,45 --size 160x90 -o '" +
                  diffraction + "x'")
                  .code,
              2);
}

TEST(Cli, BadLensFileGivesFileLineColumnAndExitCode2) {
    ff::test::TempDir dir;
    ff::test::writeFile(dir / "x.lens", "name: x\nsurfaces:\n  stop 2 1 0 5\n  12 abc 1.5 60 10\n  -50 40 1 0 10\n");
    const RunResult r = run("lens info '" + (dir / "x.lens").string() + "'");
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err, "fourierflare: error: " + (dir / "x.lens").string() +
                         ":4:6: expected a number for 'thickness', got 'abc'\n");
    EXPECT_TRUE(r.out.empty());
}

TEST(Cli, UsageErrorsExitWith2) {
    EXPECT_EQ(run("lens info").code, 2);
    EXPECT_EQ(run("frobnicate").code, 2);
    EXPECT_EQ(run("lens info lenses/double-gauss-50mm-f2.lens --wavelength abc").code, 2);
    const RunResult missing = run("lens info no-such-file.lens");
    EXPECT_EQ(missing.code, 2);
    EXPECT_TRUE(contains(missing.err, "fourierflare: error:")) << missing.err;
}

TEST(Cli, VersionAndHelp) {
    const RunResult v = run("--version");
    EXPECT_EQ(v.code, 0);
    EXPECT_TRUE(contains(v.out, "fourierflare 0.")) << v.out;
    for (const char* cmd : {"--help", "lens info --help", "lens convert --help"}) {
        const RunResult h = run(cmd);
        EXPECT_EQ(h.code, 0) << cmd;
        EXPECT_TRUE(contains(h.out, "Example:")) << cmd << ":\n" << h.out;
    }
    EXPECT_TRUE(contains(run("lens info --help").out, "587.56")) << "the default wavelength is shown";
}

TEST(Cli, ConvertWritesNativeLensAndNeverOverwritesItsInput) {
    ff::test::TempDir dir;
    const std::string dat = (dir / "dg.dat").string();
    ff::test::writeFile(dat, "29.475 3.76 1.67 25.2\n84.83 0.12 1 25.2\n19.275 4.025 1.67 23\n40.77 3.275 1.699 23\n"
                             "12.75 5.705 1 18\n0 4.5 0 17.1\n-14.495 1.18 1.603 17\n40.77 6.065 1.658 20\n"
                             "-20.385 0.19 1 20\n437.065 3.22 1.717 20\n-39.73 36.114 1 20\n");
    const std::string before = ff::test::readFile(dat);
    const RunResult same = run("lens convert '" + dat + "' -o '" + dat + "'");
    EXPECT_EQ(same.code, 2);
    EXPECT_EQ(ff::test::readFile(dat), before);

    const std::string out = (dir / "dg.lens").string();
    ASSERT_EQ(run("lens convert '" + dat + "' -o '" + out + "'").code, 0);
    const RunResult info = run("lens info '" + out + "'");
    EXPECT_EQ(info.code, 0) << info.err;
    EXPECT_TRUE(contains(info.out, "effective focal length    50.358 mm")) << info.out;
}

// The bundled GRIN rod: its gradient in the surface table and its focal length, 1 / (n0 sqrt(A)
// sin(sqrt(A) L)) = 1.849 mm for n0 = 1.608, sqrt(A) = 0.339 / mm, L = 4.26 mm.
TEST(Cli, LensInfoShowsAGradedMedium) {
    const RunResult r = run("lens info lenses/grin-rod-1.8mm-0.23-pitch.lens");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "STOP graded index (below)")) << r.out;
    EXPECT_TRUE(contains(r.out, "graded index after surface 1 at 587.6 nm (r from the axis, z from the vertex, mm): "
                                "n = 1.60800 - 0.0923965 r^2"))
        << r.out;
    EXPECT_TRUE(contains(r.out, "effective focal length    1.849 mm")) << r.out;
    EXPECT_TRUE(contains(r.out, "real-ray focal length     1.849 mm")) << r.out;
}

// A Wood lens as a .zmx GRADIENT1 surface converts to a .lens file with the same first-order data;
// a gradient on a MIRROR is refused at its place and nothing is written.
TEST(Cli, ZmxGradientsConvertAndAMirrorGradientIsRefused) {
    ff::test::TempDir dir;
    const std::string zmx = (dir / "wood.zmx").string(), out = (dir / "wood.lens").string();
    const std::string surface1 = "SURF 1\n TYPE GRADIENT1\n CURV 0\n DISZ 6\n PARM 2 1.5\n PARM 3 -0.002\n DIAM 5\n";
    const std::string rest = "SURF 2\n STOP\n CURV 0\n DISZ 30\n DIAM 5\nSURF 3\n";
    ff::test::writeFile(zmx, "UNIT MM\nSURF 0\n DISZ INFINITY\n" + surface1 + rest);
    ASSERT_EQ(run("lens convert '" + zmx + "' -o '" + out + "'").code, 0);
    const RunResult a = run("lens info '" + zmx + "'"), b = run("lens info '" + out + "'");
    ASSERT_EQ(a.code, 0) << a.err;
    ASSERT_EQ(b.code, 0) << b.err;
    // f = 1 / (n0 sqrt(A) sin(sqrt(A) d)), A = -2 a1 / n0 = 0.002667 / mm^2, d = 6 mm: 42.341 mm.
    EXPECT_TRUE(contains(a.out, "effective focal length    42.341 mm")) << a.out;
    EXPECT_TRUE(contains(b.out, "effective focal length    42.341 mm")) << b.out;
    EXPECT_TRUE(contains(b.out, "n = 1.50000 - 0.002 r^2")) << b.out;

    const std::string mirror = (dir / "mirror.zmx").string(), none = (dir / "mirror.lens").string();
    ff::test::writeFile(mirror, "SURF 0\n DISZ INFINITY\nSURF 1\n TYPE GRADIENT3\n PARM 2 1.6\n GLAS MIRROR\n" + rest);
    const RunResult m = run("lens convert '" + mirror + "' -o '" + none + "'");
    EXPECT_EQ(m.code, 2);
    EXPECT_TRUE(contains(m.err, mirror + ":6:7: a gradient-index surface cannot be a MIRROR")) << m.err;
    EXPECT_FALSE(std::filesystem::exists(none));
}

TEST(Cli, LensInfoReportsWhenTheRealRayCheckCannotBeMade) {
    // A stop 5 mm in front of the first vertex written with a negative gap (as some patents list it):
    // the paraxial data exist, the real ray launched 1 mm before the first vertex misses surface 2.
    ff::test::TempDir dir;
    ff::test::writeFile(dir / "n.lens", "name: n\nsurfaces:\n  stop -5 1 0 5\n  50 4 1.5 60 10\n  -50 40 1 0 10\n");
    const RunResult r = run("lens info '" + (dir / "n.lens").string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "effective focal length")) << r.out;
    EXPECT_TRUE(contains(r.out, "real-ray focal length     not checked: a real ray")) << r.out;
    EXPECT_TRUE(contains(r.err, "could not be checked")) << r.err;
}

TEST(Cli, LensInfoReportsAnAfocalLensAsSuch) {
    ff::test::TempDir dir;
    ff::test::writeFile(dir / "a.lens",
                        "focal_length: inf\nsurfaces:\n  stop 5 1 0 8\n  0 5 1.5 0 10\n  0 20 1 0 10\n");
    const RunResult r = run("lens info '" + (dir / "a.lens").string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "nominal focal length (header): inf (afocal)")) << r.out;
    EXPECT_TRUE(contains(r.out, "none: afocal (zero power), angular magnification 1.0000")) << r.out;
}

TEST(Cli, ErrorsPrintRawBytesEscaped) {
    // A plate that is not an image, under a name that is not UTF-8: the message names it escaped.
    ff::test::TempDir dir;
    const std::string plate = (dir / "p\xff\x1b.exr").string();
    ff::test::writeFile(plate, "garbage\xff\xfe");
    const RunResult r = run("simulate --lens lenses/double-gauss-50mm-f2.lens --plate '" + plate + "' -o '" +
                            (dir / "o.exr").string() + "'");
    EXPECT_NE(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "p\\xff\\x1b.exr")) << r.err;
    for (char c : r.err) EXPECT_TRUE(static_cast<unsigned char>(c) < 0x80 && (c >= 0x20 || c == '\n')) << int(c);
    EXPECT_FALSE(std::filesystem::exists(dir / "o.exr"));
}

// One convention (docs/cli.md): the lens is the first argument or --lens in every command; the old
// spellings of renamed options still work for one release, with a warning, and do what the new ones do.
TEST(CliConvention, TheLensIsAnArgumentOrAnOptionEverywhere) {
    const std::string lens = "lenses/cooke-triplet-50mm-f5.lens";
    const RunResult a = run("lens info " + lens), b = run("lens info --lens " + lens);
    ASSERT_EQ(a.code, 0) << a.err;
    EXPECT_EQ(a.out, b.out);
    const RunResult g1 = run("ghosts " + lens + " --angle 5 --top 3"),
                    g2 = run("ghosts --lens " + lens + " --angle 5 --top 3");
    ASSERT_EQ(g1.code, 0) << g1.err;
    EXPECT_EQ(g1.out, g2.out);
    for (const std::string cmd :
         {"lens info", "ghosts --angle 5", "table -o x.json", "export -o x.json", "compare --light 1,1 -o x"}) {
        const RunResult none = run(cmd);
        EXPECT_EQ(none.code, 2) << cmd;
        EXPECT_TRUE(contains(none.err, "a lens is required")) << cmd << ": " << none.err;
    }
    const RunResult both = run("lens info " + lens + " --lens " + lens);
    EXPECT_EQ(both.code, 2); // one or the other
}

TEST(CliConvention, OldSpellingsStillWorkWithAWarning) {
    ff::test::TempDir dir;
    const std::string lens = "lenses/cooke-triplet-50mm-f5.lens";
    const std::string env = "FF_CACHE_DIR='" + (dir / "cache").string() + "' ";
    // ghosts --azimuth: --angle DEG,AZ.
    const RunResult now = run("ghosts " + lens + " --angle 5,30 --top 3"),
                    old = run("ghosts " + lens + " --angle 5 --azimuth 30 --top 3");
    ASSERT_EQ(now.code, 0) << now.err;
    ASSERT_EQ(old.code, 0) << old.err;
    EXPECT_EQ(now.out, old.out);
    EXPECT_TRUE(contains(old.err, "--azimuth is deprecated: use --angle DEG,AZ")) << old.err;
    EXPECT_EQ(run("ghosts " + lens + " --angle 5,30 --azimuth 30").code, 2); // the azimuth twice
    // table --grid: --table-grid; the same table. The refined moment table's --max-angles and
    // --tolerance, and --sampling where nothing is traced, are read and have no effect.
    const RunResult t1 = run(
        "table " + lens + " --table-grid 8 --table-angles 5 --max-angle 8 -o '" + (dir / "a.json").string() + "'", env);
    const RunResult t2 = run("table " + lens +
                                 " --grid 8 --table-angles 5 --max-angles 20 --tolerance 0.01 --sampling reaim "
                                 "--max-angle 8 -o '" +
                                 (dir / "b.json").string() + "'",
                             env);
    ASSERT_EQ(t1.code, 0) << t1.err;
    ASSERT_EQ(t2.code, 0) << t2.err;
    EXPECT_TRUE(contains(t2.err, "--grid is deprecated: use --table-grid")) << t2.err;
    for (const char* retired : {"--max-angles", "--tolerance", "--sampling"})
        EXPECT_TRUE(contains(t2.err, std::string(retired) + " no longer has an effect")) << t2.err;
    EXPECT_FALSE(contains(t1.err, "deprecated")) << t1.err;
    EXPECT_EQ(ff::test::readFile(dir / "a.json"), ff::test::readFile(dir / "b.json"));
}

// A lens by name: the folders of FOURIERFLARE_LENS_PATH in order, then the installed lenses (none
// in a build tree; tests/install/ checks those). A file of that name wins; a path is never searched.
TEST(CliConvention, ALensByNameIsFoundOnTheLensPath) {
    ff::test::TempDir dir;
    std::filesystem::create_directories(dir / "first");
    std::filesystem::copy_file(std::string(FF_SOURCE_DIR) + "/lenses/tessar-100mm-f3.5.lens",
                               dir / "first" / "cooke-triplet-50mm-f5.lens");
    const std::string lenses = std::string(FF_SOURCE_DIR) + "/lenses";
    const std::string path = "FOURIERFLARE_LENS_PATH='" + (dir / "empty").string() + ":" + lenses + "'";
    RunResult r = run("lens info cooke-triplet-50mm-f5", path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "file: " + lenses + "/cooke-triplet-50mm-f5.lens")) << r.out;
    EXPECT_TRUE(contains(r.out, "effective focal length    50.021 mm")) << r.out;
    // The earlier folder wins, with or without the extension.
    const std::string both = "FOURIERFLARE_LENS_PATH='" + (dir / "first").string() + ":" + lenses + "'";
    for (const std::string name : {"cooke-triplet-50mm-f5", "cooke-triplet-50mm-f5.lens"}) {
        r = run("render --lens " + name + " --light 10,10 --size 32x24 --mode fitted -o '" + (dir / "x.exr").string() +
                    "' --table-grid 8 --table-angles 5",
                both + " FF_CACHE_DIR='" + (dir / "cache").string() + "'");
        EXPECT_EQ(r.code, 0) << r.err;
        r = run("lens info " + name, both);
        EXPECT_TRUE(contains(r.out, "file: " + (dir / "first").string() + "/cooke-triplet-50mm-f5.lens")) << r.out;
    }
    // A file in the working folder (the repository root) is taken as given.
    r = run("lens info lenses/cooke-triplet-50mm-f5.lens", both);
    EXPECT_TRUE(contains(r.out, "file: lenses/cooke-triplet-50mm-f5.lens")) << r.out;
    // Not found: exit 2, naming the folders searched; a path with a folder is not searched.
    r = run("lens info no-such-lens", path);
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(
        contains(r.err, "no such file, and no lens of that name in " + (dir / "empty").string() + ", " + lenses))
        << r.err;
    r = run("lens info sub/cooke-triplet-50mm-f5", path);
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "sub/cooke-triplet-50mm-f5: no such file")) << r.err;
    r = run("lens info cooke-triplet-50mm-f5", "FOURIERFLARE_LENS_PATH= FOURIERFLARE_DATA_DIR=");
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "FOURIERFLARE_LENS_PATH unset")) << r.err;
}
