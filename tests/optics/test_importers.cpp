// Importers: files written here from tables 2 and 4 of lenses.md must import to the same first-order
// data as the bundled .lens files.

#include "core/error.h"
#include "core/units.h"
#include "optics/dat_importer.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/lens_writer.h"
#include "optics/paraxial.h"
#include "optics/zmx_importer.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "test_support.h"

using namespace ff;
using namespace ff::optics;

namespace {

// lenses.md table 2 (double Gauss 50 mm): radius, thickness, nd, semi-aperture.
const double kTable2[][4] = {{29.475, 3.76, 1.670, 12.6},  {84.83, 0.12, 1, 12.6},      {19.275, 4.025, 1.670, 11.5},
                             {40.77, 3.275, 1.699, 11.5},  {12.75, 5.705, 1, 9.0},      {0, 4.5, 1, 8.55},
                             {-14.495, 1.18, 1.603, 8.5},  {40.77, 6.065, 1.658, 10.0}, {-20.385, 0.19, 1, 10.0},
                             {437.065, 3.22, 1.717, 10.0}, {-39.73, 36.114, 1, 10.0}};

std::string datFromTable2(bool positions) {
    std::string s = "# D-GAUSS F/2 22deg HFOV\n# radius thickness eta aperture-diameter\n";
    double z = 0.0;
    for (const auto& r : kTable2) {
        char line[128];
        const double eta = r[2] == 1.0 ? 0.0 : r[2]; // pbrt: 0 means air
        std::snprintf(line, sizeof line, "%g\t%g\t%g\t%g\n", r[0], positions ? z : r[1], eta, 2.0 * r[3]);
        s += line;
        z += r[1];
    }
    return s;
}

// lenses.md table 4 (double Gauss 100 mm, catalogue glasses).
struct Row4 {
    double radius, thickness;
    const char* glass;
    double nd, vd, semi;
    bool stop;
};
const Row4 kTable4[] = {{56.20238, 8.75, "N-SSK2", 1.62229, 53.27, 39.44, false},
                        {152.2858, 0.5, "", 0, 0, 35.74, false},
                        {37.68262, 12.5, "N-SK2", 1.60738, 56.65, 35.47, false},
                        {0, 3.8, "F5", 1.60342, 38.03, 26.82, false},
                        {24.2313, 16.369445, "", 0, 0, 24.19, false},
                        {0, 13.747957, "", 0, 0, 15.85, true},
                        {-28.37731, 3.8, "F5", 1.60342, 38.03, 19.66, false},
                        {0, 11, "N-SK16", 1.62041, 60.32, 21.31, false},
                        {-37.92546, 0.5, "", 0, 0, 26.03, false},
                        {177.41176, 7, "N-SK16", 1.62041, 60.32, 26.16, false},
                        {-79.41143, 61.487536, "", 0, 0, 26.93, false}};

std::string zmxFromTable4(double unitMm = 1.0, const char* unit = "MM") {
    std::string s = "VERS 190513 80 123457 L123457\nMODE SEQ\nNAME Double Gauss F/2\nUNIT " + std::string(unit) +
                    " X W X CM MR CPMM\nENPD 50\nSURF 0\n  TYPE STANDARD\n  CURV 0.0 0 0 0 0 \"\"\n  DISZ INFINITY\n";
    char buf[256];
    int n = 1;
    for (const Row4& r : kTable4) {
        std::snprintf(buf, sizeof buf, "SURF %d\n  TYPE STANDARD\n  CURV %.17g 0 0 0 0 \"\"\n  DISZ %.17g\n", n++,
                      r.radius == 0.0 ? 0.0 : unitMm / r.radius, r.thickness / unitMm);
        s += buf;
        if (r.stop) s += "  STOP\n";
        if (*r.glass) {
            std::snprintf(buf, sizeof buf, "  GLAS %s 0 0 %.5f %.2f 0 0 0 0 0 0\n", r.glass, r.nd, r.vd);
            s += buf;
        }
        std::snprintf(buf, sizeof buf, "  DIAM %.17g 1 0 0 1 \"\"\n  POPS 0 0 0 0 0 0 0 0 1 1 1 1 0 0 0 0\n",
                      r.semi / unitMm);
        s += buf;
    }
    std::snprintf(buf, sizeof buf, "SURF %d\n  TYPE STANDARD\n  CURV 0.0 0 0 0 0 \"\"\n  DISZ 0\n", n);
    return s + buf;
}

std::string utf16le(const std::string& ascii, bool bom) {
    std::string out = bom ? std::string("\xFF\xFE", 2) : std::string();
    for (char c : ascii) {
        out += c;
        out += '\0';
    }
    return out;
}

double efl(const Lens& lens) {
    return paraxialEfl(lens, lines::d);
}

} // namespace

TEST(DatImporter, Table2ImportsToTheSameFocalLengthAsTheLensFile) {
    const Lens reference = loadLens(test::lensPath("double-gauss-50mm-f2.lens"));
    CollectingReporter rep;
    const Lens dat = importDat(datFromTable2(false), "dgauss.dat", &rep);
    EXPECT_NEAR(efl(dat), efl(reference), 1e-9 * efl(reference));
    EXPECT_NEAR(paraxialBfd(dat, lines::d), 36.1059, 1e-4);
    EXPECT_EQ(dat.name, "D-GAUSS F/2 22deg HFOV");
    EXPECT_TRUE(dat.surfaces[5].stop);
    EXPECT_EQ(dat.surfaces[5].semiAperture, 8.55);
    EXPECT_FALSE(dat.imageDistanceAuto);
    EXPECT_NEAR(dat.surfaces.back().thickness, 36.114, 1e-12);
}

TEST(DatImporter, DetectsAxialPositionsAndSaysSo) {
    CollectingReporter rep;
    const Lens dat = importDat(datFromTable2(true), "axpos.dat", &rep);
    EXPECT_NEAR(efl(dat), 50.3582, 1e-4);
    EXPECT_TRUE(dat.imageDistanceAuto);
    EXPECT_NEAR(dat.surfaces.back().thickness, 36.1059, 1e-4);
    ASSERT_FALSE(rep.diagnostics.empty());
    EXPECT_NE(rep.diagnostics[0].message.find("read as axial positions"), std::string::npos);
}

TEST(DatImporter, LastThicknessZeroFocusesAtTheParaxialImage) {
    std::string text = datFromTable2(false);
    text.replace(text.find("36.114"), 6, "0");
    const Lens dat = importDat(text, "focus.dat");
    EXPECT_TRUE(dat.imageDistanceAuto);
    EXPECT_NEAR(dat.surfaces.back().thickness, 36.1059, 1e-4);
}

TEST(DatImporter, RejectsMalformedRows) {
    try {
        importDat("# x\n10 2 1.5\n", "bad.dat");
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "bad.dat:2:10: expected 4 values per row (radius thickness eta aperture-diameter), found 3");
    }
    try {
        importDat("10 2 1.5 x\n", "bad.dat");
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "bad.dat:1:10: expected a number for 'aperture diameter', got 'x'");
    }
}

TEST(ZmxImporter, Table4ImportsToEfl100004) {
    const Lens reference = loadLens(test::lensPath("double-gauss-100mm-f2.lens"));
    CollectingReporter rep;
    const Lens zmx = importZmx(zmxFromTable4(), "dg.zmx", &rep);
    EXPECT_NEAR(efl(zmx), 100.004, 1e-4 * 100.004);
    EXPECT_NEAR(efl(zmx), efl(reference), 1e-9 * 100.0);
    EXPECT_EQ(zmx.name, "Double Gauss F/2");
    EXPECT_EQ(zmx.surfaces[0].medium.glass, "N-SSK2");
    EXPECT_TRUE(zmx.surfaces[5].stop);
    EXPECT_NEAR(zmx.surfaces[5].semiAperture, 15.85, 1e-12);
    // POPS, VERS, MODE are not part of the prescription: ignored and counted.
    bool counted = false;
    for (const auto& d : rep.diagnostics)
        counted = counted || d.message.find("ignored 13 directive(s)") != std::string::npos;
    EXPECT_TRUE(counted);
}

TEST(ZmxImporter, Utf16FilesImportTheSame) {
    const double expected = efl(importZmx(zmxFromTable4(), "a.zmx"));
    EXPECT_EQ(efl(importZmx(utf16le(zmxFromTable4(), true), "bom.zmx")), expected);
    EXPECT_EQ(efl(importZmx(utf16le(zmxFromTable4(), false), "nobom.zmx")), expected);
}

TEST(ZmxImporter, LensUnitsAreConvertedToMillimetres) {
    const double mm = efl(importZmx(zmxFromTable4(), "mm.zmx"));
    EXPECT_NEAR(efl(importZmx(zmxFromTable4(25.4, "IN"), "in.zmx")), mm, 1e-9 * mm);
    EXPECT_NEAR(efl(importZmx(zmxFromTable4(10.0, "CM"), "cm.zmx")), mm, 1e-9 * mm);
}

TEST(ZmxImporter, EvenAsphereTermsAreScaledWithTheUnit) {
    // In inches, sag(r) = A4 r^4 with A4 = 1e-3 in^-3; in mm the coefficient is A4 / 25.4^3.
    const std::string text =
        "UNIT IN\nSURF 0\n DISZ INFINITY\nSURF 1\n TYPE EVENASPH\n STOP\n CURV 0.02\n DISZ 0.2\n"
        " GLAS N-BK7 0 0 1.5168 64.17\n PARM 2 1e-3\n DIAM 0.5\nSURF 2\n CURV 0\n DISZ 3\nSURF 3\n";
    const Lens lens = importZmx(text, "asph.zmx");
    ASSERT_EQ(lens.surfaces[0].asphere.size(), 1u);
    EXPECT_NEAR(lens.surfaces[0].asphere[0], 1e-3 / (25.4 * 25.4 * 25.4), 1e-18);
    EXPECT_NEAR(lens.surfaces[0].radius, 50.0 * 25.4, 1e-9);
}

// OpticStudio's biconic in inches: CURV and CONI the y-z section, PARM 1 the X radius (a length,
// scaled with the unit), PARM 2 the X conic; a cylinder (CURV 0: flat in y) the same way. `lens
// convert`'s .lens reads back as the same surfaces, and the first-order data follow the sections.
TEST(ZmxImporter, BiconicSurfacesKeepBothSections) {
    const std::string text =
        "UNIT IN\nSURF 0\n DISZ INFINITY\nSURF 1\n TYPE BICONICX\n CURV 0.5\n CONI -0.4\n"
        " PARM 1 4\n PARM 2 0.3\n DISZ 0.2\n GLAS N-BK7\n DIAM 0.5\nSURF 2\n STOP\n DISZ 0.1\n"
        " DIAM 0.3\nSURF 3\n TYPE BICONICX\n CURV 0\n PARM 1 -3\n DISZ 0.1\n GLAS N-BK7\n DIAM 0.5\n"
        "SURF 4\n DISZ 2\nSURF 5\n";
    const Lens lens = importZmx(text, "bi.zmx");
    ASSERT_EQ(lens.surfaces.size(), 4u);
    const Surface &a = lens.surfaces[0], &b = lens.surfaces[2];
    EXPECT_EQ(a.shape, SurfaceShape::Biconic);
    EXPECT_NEAR(a.radius, 2.0 * 25.4, 1e-12);
    EXPECT_EQ(a.conic, -0.4);
    EXPECT_NEAR(a.radiusX, 4.0 * 25.4, 1e-12);
    EXPECT_EQ(a.conicX, 0.3);
    EXPECT_EQ(b.shape, SurfaceShape::Biconic);
    EXPECT_EQ(b.curvatureY(), 0.0);
    EXPECT_NEAR(b.radiusX, -3.0 * 25.4, 1e-12);
    const Lens again = parseLensText(writeLensText(lens), "bi.lens");
    for (std::size_t i = 0; i < lens.surfaces.size(); ++i) {
        EXPECT_EQ(again.surfaces[i].shape, lens.surfaces[i].shape) << i;
        EXPECT_EQ(again.surfaces[i].radius, lens.surfaces[i].radius) << i;
        EXPECT_EQ(again.surfaces[i].radiusX, lens.surfaces[i].radiusX) << i;
        EXPECT_EQ(again.surfaces[i].conicX, lens.surfaces[i].conicX) << i;
    }
    // The x-z section (the lens of the X radii) survives the conversion.
    EXPECT_EQ(analyzeFirstOrder(sectionOf(lens, Section::X), lines::d).efl,
              analyzeFirstOrder(sectionOf(again, Section::X), lines::d).efl);
}

TEST(ZmxImporter, RefusesWhatItCannotRepresent) {
    const std::pair<std::string, const char*> cases[] = {
        {"SURF 0\n DISZ INFINITY\nSURF 1\n  TYPE COORDBRK\nSURF 2\nSURF 3\n",
         "c.zmx:4:8: unsupported surface type 'COORDBRK'; supported: STANDARD, EVENASPH, BICONICX, GRADIENT1, "
         "GRADIENT3 (sequential lenses)"},
        {"SURF 0\n DISZ INFINITY\nSURF 1\n  TYPE TOROIDAL\nSURF 2\nSURF 3\n",
         "c.zmx:4:8: TOROIDAL surfaces are not supported (a torus has no exact shape here); give the surface as "
         "BICONICX, its X radius as PARM 1"},
        {"SURF 0\n DISZ INFINITY\nSURF 1\n  TYPE BICONICX\n  PARM 3 0.5\nSURF 2\n",
         "c.zmx:4:8: BICONICX with PARM 3 is not supported (only PARM 1, the X radius, and PARM 2, the X conic)"},
        {"SURF 0\nSURF 1\n  GLAS MIRROR\nSURF 2\n",
         "c.zmx:3:8: MIRROR surfaces (catadioptric systems) are not supported"},
        {"SURF 0\nSURF 1\n", "c.zmx:3: expected at least an object surface (SURF 0), one lens surface and an image "
                             "surface, found 2 SURF block(s)"},
        {"SURF 0\nSURF 2\n", "c.zmx:2:6: expected SURF 1 (surfaces in order), got SURF 2"},
        {"UNIT FT\n", "c.zmx:1:6: unknown lens unit 'FT'; valid units: MM, CM, IN, METER"},
        {"SURF 0\nSURF 1\n CURV 1/50\n", "c.zmx:3:7: expected a curvature after CURV, got '1/50'"},
        {"CURV 0.1\n", "c.zmx:1:1: CURV outside a SURF block"},
        {"SURF 0\nSURF 1\n PARM 1e120 0\n", "c.zmx:3:7: expected a parameter number 0..99 after PARM"},
        {"SURF 0\nSURF 1\n GLAS SF-11\nSURF 2\nSURF 3\n",
         "c.zmx:3:7: unknown glass 'SF-11'; did you mean N-SF11, SF1 or N-SF1? (the catalogue is data/glass/; give 'nd "
         "Vd' instead for other glasses)"},
    };
    for (const auto& [text, expected] : cases) {
        try {
            importZmx(text, "c.zmx");
            ADD_FAILURE() << "accepted:\n" << text;
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()), expected) << text;
        }
    }
}

TEST(ZmxImporter, UnknownGlassWithInlineDataFallsBackWithANote) {
    const std::string text =
        "SURF 0\n DISZ INFINITY\nSURF 1\n STOP\n CURV 0.02\n DISZ 4\n GLAS ___BLANK 1 0 1.6 40\n DIAM 8\n"
        "SURF 2\n CURV -0.01\n DISZ 40\n DIAM 8\nSURF 3\n";
    CollectingReporter rep;
    const Lens lens = importZmx(text, "blank.zmx", &rep);
    EXPECT_EQ(lens.surfaces[0].medium.nd, 1.6);
    EXPECT_EQ(lens.surfaces[0].medium.vd, 40.0);
    ASSERT_FALSE(rep.diagnostics.empty());
    EXPECT_EQ(rep.diagnostics[0].str(),
              "blank.zmx:7:7: glass '___BLANK' is not in the catalogue; using its inline nd 1.6, Vd 40 (Cauchy)");
}

TEST(ZmxImporter, GlasAirIsAir) {
    std::string text = zmxFromTable4();
    text.replace(text.find("  DISZ 0.5\n"), 11, "  DISZ 0.5\n  GLAS AIR\n");
    const Lens lens = importZmx(text, "air.zmx");
    EXPECT_TRUE(lens.surfaces[1].medium.isAir());
    EXPECT_NEAR(efl(lens), 100.004, 1e-2);
}

// A Wood lens as an OpticStudio GRADIENT1 surface in centimetres: a flat slab with n = n0 + nr2 r^2.
// Paraxially r'' = -A r inside (A = -2 nr2 / n0), so f = 1 / (n0 sqrt(A) sin(sqrt(A) d)).
TEST(ZmxImporter, Gradient1IsAWoodLensInMillimetres) {
    const double n0 = 1.55, nr2cm = -0.25, dcm = 0.6; // nr2 in cm^-2: -0.0025 mm^-2
    const std::string text = "UNIT CM\nSURF 0\n DISZ INFINITY\nSURF 1\n TYPE GRADIENT1\n CURV 0\n DISZ 0.6\n"
                             " PARM 1 0.05\n PARM 2 1.55\n PARM 3 -0.25\n DIAM 0.5\n"
                             "SURF 2\n STOP\n CURV 0\n DISZ 10\n DIAM 0.5\nSURF 3\n";
    CollectingReporter rep;
    const Lens lens = importZmx(text, "wood.zmx", &rep);
    const Medium& m = lens.surfaces[0].medium;
    ASSERT_TRUE(m.gradient);
    EXPECT_EQ(m.index(400.0), n0);
    EXPECT_EQ(m.index(700.0), n0);
    ASSERT_EQ(m.gradient->radial.size(), 1u);
    EXPECT_NEAR(m.gradient->radial[0].atD, nr2cm / 100.0, 1e-18);
    EXPECT_TRUE(m.gradient->axial.empty());
    EXPECT_EQ(m.gradient->origin.str(), "wood.zmx:5:7");
    const double A = -2.0 * (nr2cm / 100.0) / n0, d = dcm * 10.0;
    EXPECT_NEAR(efl(lens) / (1.0 / (n0 * std::sqrt(A) * std::sin(std::sqrt(A) * d))), 1.0, 1e-9);
    ASSERT_FALSE(rep.diagnostics.empty());
    EXPECT_EQ(rep.diagnostics[0].str(), "wood.zmx:5:7: GRADIENT1: n0 1.55 and its coefficients at every wavelength");
}

// GRADIENT3's parameters map to n0, r^2, r^4, r^6 and z, z^2, z^3 (inches: r^(2k) terms divided by
// 25.4^(2k), z^k terms by 25.4^k); the glass column is not used.
TEST(ZmxImporter, Gradient3MapsEveryCoefficientWithTheUnit) {
    const std::string text = "UNIT IN\nSURF 0\n DISZ INFINITY\nSURF 1\n TYPE GRADIENT3\n STOP\n CURV 0.05\n"
                             " DISZ 0.25\n GLAS N-BK7 0 0 1.5168 64.17\n PARM 1 0.01\n PARM 2 1.6\n"
                             " PARM 3 -0.01\n PARM 4 2e-4\n PARM 5 -3e-6\n PARM 6 0.02\n PARM 7 -1e-3\n"
                             " PARM 8 5e-5\n DIAM 0.3\nSURF 2\n CURV -0.02\n DISZ 2\n DIAM 0.3\nSURF 3\n";
    CollectingReporter rep;
    const Lens lens = importZmx(text, "g3.zmx", &rep);
    const Medium& m = lens.surfaces[0].medium;
    ASSERT_TRUE(m.gradient);
    EXPECT_EQ(m.index(486.0), 1.6);
    const double in = 25.4;
    const double radial[] = {-0.01 / (in * in), 2e-4 / std::pow(in, 4), -3e-6 / std::pow(in, 6)};
    const double axial[] = {0.02 / in, -1e-3 / (in * in), 5e-5 / (in * in * in)};
    ASSERT_EQ(m.gradient->radial.size(), 3u);
    ASSERT_EQ(m.gradient->axial.size(), 3u);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(m.gradient->radial[k].atD / radial[k], 1.0, 1e-14) << k;
        EXPECT_NEAR(m.gradient->axial[k].atD / axial[k], 1.0, 1e-14) << k;
        EXPECT_EQ(m.gradient->radial[k].dispersion, 0.0);
    }
    EXPECT_EQ(rep.diagnostics[0].str(),
              "g3.zmx:5:7: GRADIENT3: n0 1.6 and its coefficients at every wavelength; the glass 'N-BK7' is not used");
}

TEST(ZmxImporter, RefusesGradientsItCannotRepresent) {
    const std::string head = "SURF 0\n DISZ INFINITY\nSURF 1\n";
    const std::string tail = " CURV 0\n DISZ 5\n DIAM 4\nSURF 2\n STOP\n DISZ 20\n DIAM 4\nSURF 3\n";
    const std::pair<std::string, const char*> cases[] = {
        {head + " TYPE GRADIENT3\n PARM 2 1.6\n GLAS MIRROR\n" + tail,
         "g.zmx:6:7: a gradient-index surface cannot be a MIRROR"},
        {head + " TYPE GRADIENT1\n PARM 3 -0.001\n" + tail,
         "g.zmx:4:7: GRADIENT1 needs its base index n0 > 1 as PARM 2"},
        {head + " TYPE GRADIENT5\n" + tail,
         "g.zmx:4:7: unsupported surface type 'GRADIENT5'; supported: STANDARD, EVENASPH, BICONICX, GRADIENT1, "
         "GRADIENT3 (sequential lenses; Gradient 5, 6, 9, 12 and GRADIUM take their index from "
         "dispersion files (SGRIN.DAT, GLC.DAT, GRADIENT_9.DAT, PROFILE.GRD) that a .zmx does not carry, and "
         "Gradient 2, 4, 7 and 10 are not polynomials in r^2 and z: convert them to grin_r=/grin_z= in a .lens "
         "file)"},
        // n = 1.2 - 0.1 r^2 falls to 1 at r = sqrt(2) mm; the first of the checked radii (4 mm k / 32)
        // beyond it is 1.5 mm.
        {head + " TYPE GRADIENT1\n PARM 2 1.2\n PARM 3 -0.1\n" + tail, nullptr},
    };
    for (const auto& [text, expected] : cases) {
        try {
            importZmx(text, "g.zmx");
            ADD_FAILURE() << "accepted:\n" << text;
        } catch (const Error& e) {
            const std::string what = e.what();
            if (expected) {
                EXPECT_EQ(what, expected) << text;
            } else {
                EXPECT_EQ(what.rfind("g.zmx:4:7: the graded index is 0.97", 0), 0u) << what;
                EXPECT_NE(what.find("at r = 1.500 mm, z = 0.000 mm"), std::string::npos) << what;
            }
        }
    }
}

TEST(LensLoader, DispatchesByExtensionAndRefusesOthers) {
    test::TempDir dir;
    test::writeFile(dir / "a.dat", datFromTable2(false));
    test::writeFile(dir / "a.zmx", utf16le(zmxFromTable4(), true));
    test::writeFile(dir / "a.txt", "x");
    EXPECT_NEAR(efl(loadLens(dir / "a.dat")), 50.3582, 1e-4);
    EXPECT_NEAR(efl(loadLens(dir / "a.zmx")), 100.004, 1e-2);
    EXPECT_EQ(loadLens(dir / "a.dat").format, "dat");
    EXPECT_THROW(loadLens(dir / "a.txt"), Error);
    EXPECT_THROW(loadLens(dir / "missing.lens"), Error);
}
