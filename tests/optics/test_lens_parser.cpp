#include "core/units.h"
#include "optics/lens_parser.h"
#include "optics/paraxial.h"
#include "optics/zoom.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace ff;
using namespace ff::optics;

TEST(LensParser, ReadsTheFlareSimFormatAsIs) {
    const char* text = R"(# comment
name: Canon FL200mm F3.5
focal_length: 200.00          # nominal

surfaces:
# radius   thickness   ior      abbe   semi_ap   coating
  84.0     10.6        1.62280  0.00   57.200    1
  -300     5           1        0      57.2      0
  stop     4.1         1.00000  0.00   26.329    0
  -90      3           1.6      40     30        1
  200      150         1.0      0.0    30        0
)";
    CollectingReporter rep;
    const Lens lens = parseLensText(text, "fl.lens", &rep);
    EXPECT_EQ(lens.name, "Canon FL200mm F3.5");
    ASSERT_TRUE(lens.nominalFocalLength);
    EXPECT_EQ(*lens.nominalFocalLength, 200.0);
    ASSERT_EQ(lens.surfaces.size(), 5u);
    EXPECT_EQ(lens.surfaces[0].radius, 84.0);
    EXPECT_EQ(lens.surfaces[0].medium.nd, 1.6228);
    EXPECT_EQ(lens.surfaces[0].medium.index(450), 1.6228); // abbe 0: non-dispersive
    EXPECT_TRUE(lens.surfaces[1].medium.isAir());
    EXPECT_TRUE(lens.surfaces[2].stop);
    EXPECT_TRUE(lens.surfaces[2].flatStopRow);
    EXPECT_EQ(lens.surfaces[2].radius, 0.0);
    EXPECT_EQ(lens.surfaces[2].semiAperture, 26.329);
    EXPECT_EQ(lens.stopIndex(), 2u);
    EXPECT_EQ(lens.surfaces[3].coatingLayers, 1);
    EXPECT_EQ(lens.coatingOf(3), CoatingSpec::mgf2());
    EXPECT_EQ(lens.coatingOf(1), CoatingSpec::none());
    EXPECT_EQ(lens.surfaces[2].origin.str(), "fl.lens:9:3");
    EXPECT_TRUE(rep.diagnostics.empty());
}

TEST(LensParser, ReadsTheExtensions) {
    const char* text = R"(name: Extended
source: a test
patent: US 1,234,567
f_number: 16
sensor: 36 x 24
aperture_blades: 7
blade_rotation: 12.5
coating: stack(MgF2:0.25, ZrO2:0.5, Al2O3:0.25) 520
zoom_positions: wide tele

surfaces:
  30       4            N-BK7       12    1    conic=-0.5 asph=1e-6,-2e-9
  -50      2,8          air         12    1
  20       3            F2          9     1    stop
  -40      auto         1 0         9     2    coating=mgf2@600
  0        0            1 0         0     0    toric 25
)";
    // The last row is deliberately odd (a toric flat after 'auto'), see below.
    EXPECT_THROW(parseLensText(text, "x.lens"), Error); // 'auto' not on the last row
    std::string fixedText = text;
    fixedText.replace(fixedText.find("auto"), 4, "30  ");
    fixedText.replace(fixedText.rfind("0        0  "), 12, "0        40 ");
    CollectingReporter rep;
    const Lens lens = parseLensText(fixedText, "x.lens", &rep);
    EXPECT_EQ(lens.source, "a test");
    EXPECT_EQ(lens.patent, "US 1,234,567");
    EXPECT_EQ(*lens.fNumber, 16.0);
    EXPECT_EQ(lens.sensorMm->first, 36.0);
    EXPECT_EQ(lens.sensorMm->second, 24.0);
    EXPECT_EQ(lens.apertureBlades, 7);
    EXPECT_EQ(lens.bladeRotationDeg, 12.5);
    ASSERT_TRUE(lens.defaultCoating);
    EXPECT_EQ(lens.defaultCoating->layers.size(), 3u);
    EXPECT_EQ(lens.defaultCoating->lambda0Nm, 520.0);
    EXPECT_EQ(lens.surfaces[0].medium.glass, "N-BK7");
    EXPECT_EQ(lens.surfaces[0].conic, -0.5);
    ASSERT_EQ(lens.surfaces[0].asphere.size(), 2u);
    EXPECT_EQ(lens.surfaces[0].asphere[1], -2e-9);
    EXPECT_EQ(lens.zoomLabels, (std::vector<std::string>{"wide", "tele"}));
    EXPECT_EQ(lens.zoomGaps[1], (std::vector<double>{2.0, 8.0}));
    EXPECT_EQ(lens.surfaces[1].thickness, 2.0);
    EXPECT_EQ(atZoom(lens, 1).surfaces[1].thickness, 8.0);
    EXPECT_TRUE(lens.surfaces[2].stop);
    EXPECT_FALSE(lens.surfaces[2].flatStopRow);
    EXPECT_EQ(lens.coatingOf(0), *lens.defaultCoating);     // column 1 -> lens-wide coating
    EXPECT_EQ(lens.coatingOf(3), CoatingSpec::mgf2(600.0)); // explicit per-surface spec wins
    EXPECT_EQ(lens.surfaces[4].shape, SurfaceShape::Toric);
    EXPECT_EQ(lens.surfaces[4].radiusY, 25.0);
    EXPECT_FALSE(lens.rotationallySymmetric());
    // Two notes: the unclipped surface 5 (semi_ap 0) and its anamorphic shape.
    ASSERT_EQ(rep.diagnostics.size(), 2u);
    EXPECT_EQ(rep.diagnostics[0].str(),
              "x.lens:16:3: surface 5 has semi-aperture 0 (not given): it is treated as unclipped");
}

TEST(LensParser, AutoImageDistanceIsTheParaxialFocus) {
    const Lens lens = parseLensText("surfaces:\n  stop 1 1 0 5\n  50 4 1.5 60 10\n  -50 auto 1 0 10\n", "a.lens");
    EXPECT_TRUE(lens.imageDistanceAuto);
    EXPECT_NEAR(lens.surfaces.back().thickness, paraxialBfd(lens, lines::d), 1e-12);
}

TEST(LensParser, GlassRowsMayOmitTheCoatingColumn) {
    // Without a coating column a glass-air interface is coated (lens-wide default), others are not.
    const Lens lens =
        parseLensText("surfaces:\n  stop 2 air 5\n  50 4 N-BK7 10\n  -50 1 N-SF11 10\n  -80 40 air 10\n", "g.lens");
    EXPECT_EQ(lens.surfaces[0].coatingLayers, 0);
    EXPECT_EQ(lens.surfaces[1].coatingLayers, 1);
    EXPECT_EQ(lens.surfaces[2].coatingLayers, 0);
    EXPECT_EQ(lens.surfaces[3].coatingLayers, 1);
    EXPECT_EQ(lens.surfaces[2].medium.glass, "N-SF11");
}

TEST(LensParser, ToleratesCrLfAndBom) {
    const Lens lens =
        parseLensText("\xEF\xBB\xBFname: w\r\nsurfaces:\r\n  stop 1 1 0 5\r\n  50 40 1 0 10\r\n", "w.lens");
    EXPECT_EQ(lens.name, "w");
    EXPECT_EQ(lens.surfaces.size(), 2u);
}

// The rules for the patent-converted libraries' quirks (each quirk a file written here).

namespace {
bool said(const CollectingReporter& rep, const std::string& text) {
    for (const Diagnostic& d : rep.diagnostics)
        if (d.message.find(text) != std::string::npos) return true;
    return false;
}
} // namespace

TEST(LensParser, WithoutAStopRowTheSurfaceLimitingTheAxialBeamIsTheStop) {
    // A biconvex singlet (f ~ 50 mm) then a flat surface of semi-aperture 3 mm 20 mm behind it. The
    // marginal ray from infinity has height 1 at the singlet and, converging towards a focus ~50 mm
    // away, between 0.3 and 1 at the flat surface: 3 / y there is under 10 = 10 / y at the singlet
    // (y ~ 1), so the flat surface limits the axial beam.
    CollectingReporter rep;
    const Lens lens = parseLensText("surfaces:\n  50 4 1.5 60 10\n  -50 20 1 0 10\n  0 30 1 0 3\n", "n.lens", &rep);
    EXPECT_TRUE(lens.stopInferred);
    EXPECT_EQ(lens.stopIndex(), 2u);
    const double y = heightAt(lens, lines::d, {1.0, 0.0}, 0, 2);
    EXPECT_GT(y, 0.3);
    EXPECT_LT(y, 1.0);
    EXPECT_TRUE(said(rep, "no stop row: surface 3 limits the axial beam"));
    // The same prescription with the limiting surface wider: the singlet's front now limits.
    const Lens wide = parseLensText("surfaces:\n  50 4 1.5 60 10\n  -50 20 1 0 10\n  0 30 1 0 9.5\n", "w.lens");
    EXPECT_EQ(wide.stopIndex(), 0u);
    // Nothing limits the beam (no semi-aperture anywhere): refused, saying why.
    try {
        parseLensText("surfaces:\n  50 4 1.5 60 0\n  -50 40 1 0 0\n", "z.lens");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(e.message().find("no surface limits the axial beam"), std::string::npos) << e.message();
    }
}

TEST(LensParser, ALastThicknessOfZeroIsTheParaxialFocus) {
    CollectingReporter rep;
    const Lens zero = parseLensText("surfaces:\n  stop 1 1 0 5\n  50 4 1.5 60 10\n  -50 0 1 0 10\n", "z.lens", &rep);
    EXPECT_TRUE(zero.imageDistanceAuto);
    EXPECT_TRUE(said(rep, "last thickness 0: read as 'auto'"));
    // The sensor at the paraxial focus: a ray parallel to the axis crosses it there.
    const ParaxialRay out = traceParaxial(zero, lines::d, {1.0, 0.0}, 0, zero.surfaces.size());
    EXPECT_NEAR(out.y + zero.surfaces.back().thickness * out.w, 0.0, 1e-12);
    EXPECT_GT(zero.surfaces.back().thickness, 0.0);
    EXPECT_THROW(parseLensText("surfaces:\n  stop 1 1 0 5\n  50 4 1.5 60 10\n  -50 -3 1 0 10\n", "n.lens"), Error);
}

TEST(LensParser, AnInfiniteFocalLengthIsAfocalAndAHugeSemiApertureIsUnlimited) {
    CollectingReporter rep;
    const Lens lens =
        parseLensText("focal_length: inf\nsurfaces:\n  stop 5 1 0 8\n  0 5 1.5 0 1e6\n  0 20 1 0 10\n", "a.lens", &rep);
    ASSERT_TRUE(lens.nominalFocalLength);
    EXPECT_TRUE(std::isinf(*lens.nominalFocalLength));
    EXPECT_EQ(lens.surfaces[1].semiAperture, 0.0); // unclipped
    EXPECT_TRUE(said(rep, "read as unlimited"));
    // A flat plate has no power: refused by default, described when asked.
    EXPECT_THROW(analyzeFirstOrder(lens, lines::d), Error);
    const FirstOrder f = analyzeFirstOrder(lens, lines::d, /*allowAfocal=*/true);
    EXPECT_TRUE(f.afocal);
    EXPECT_TRUE(std::isinf(f.efl));
    EXPECT_NEAR(f.angularMagnification, 1.0, 1e-12); // a plate turns no ray
}
