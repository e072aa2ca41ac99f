#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/lens_writer.h"
#include "optics/paraxial.h"
#include "optics/zmx_importer.h"

#include <gtest/gtest.h>

#include <utility>

#include "test_support.h"

using namespace ff;
using namespace ff::optics;

namespace {

void expectSamePrescription(const Lens& a, const Lens& b, const std::string& what) {
    EXPECT_EQ(a.name, b.name) << what;
    EXPECT_EQ(a.source, b.source) << what;
    EXPECT_EQ(a.fNumber, b.fNumber) << what;
    EXPECT_EQ(a.sensorMm, b.sensorMm) << what;
    EXPECT_EQ(a.zoomLabels, b.zoomLabels) << what;
    EXPECT_EQ(a.zoomGaps, b.zoomGaps) << what;
    EXPECT_EQ(a.imageDistanceAuto, b.imageDistanceAuto) << what;
    ASSERT_EQ(a.surfaces.size(), b.surfaces.size()) << what;
    for (std::size_t i = 0; i < a.surfaces.size(); ++i) {
        const Surface &x = a.surfaces[i], &y = b.surfaces[i];
        const std::string at = what + " surface " + std::to_string(i + 1);
        EXPECT_EQ(x.radius, y.radius) << at;
        EXPECT_EQ(x.thickness, y.thickness) << at;
        EXPECT_EQ(x.conic, y.conic) << at;
        EXPECT_EQ(x.asphere, y.asphere) << at;
        EXPECT_EQ(x.semiAperture, y.semiAperture) << at;
        EXPECT_EQ(x.stop, y.stop) << at;
        EXPECT_EQ(x.medium.glass, y.medium.glass) << at;
        EXPECT_EQ(x.medium.index(450.0), y.medium.index(450.0)) << at;
        EXPECT_EQ(a.coatingOf(i), b.coatingOf(i)) << at;
        EXPECT_EQ(x.shape, y.shape) << at;
        EXPECT_EQ(x.radiusX, y.radiusX) << at;
        EXPECT_EQ(x.conicX, y.conicX) << at;
        ASSERT_EQ(x.medium.gradient.has_value(), y.medium.gradient.has_value()) << at;
        if (!x.medium.gradient) continue;
        for (const auto& [p, q] : {std::pair{&x.medium.gradient->radial, &y.medium.gradient->radial},
                                   std::pair{&x.medium.gradient->axial, &y.medium.gradient->axial}}) {
            ASSERT_EQ(p->size(), q->size()) << at;
            for (std::size_t k = 0; k < p->size(); ++k) {
                EXPECT_EQ((*p)[k].atD, (*q)[k].atD) << at;
                EXPECT_EQ((*p)[k].dispersion, (*q)[k].dispersion) << at;
            }
        }
    }
}

} // namespace

TEST(LensWriter, EveryBundledLensRoundTrips) {
    for (const auto& entry : std::filesystem::directory_iterator(test::sourceDir() / "lenses")) {
        if (entry.path().extension() != ".lens") continue;
        const Lens original = loadLens(entry.path());
        const Lens again = parseLensText(writeLensText(original), "again.lens");
        expectSamePrescription(original, again, entry.path().filename().string());
        EXPECT_EQ(paraxialEfl(original, lines::d), paraxialEfl(again, lines::d));
    }
}

TEST(LensWriter, ExtensionsRoundTrip) {
    const char* text = "name: x\ncoating: mgf2 600\nzoom_positions: a b\nsurfaces:\n"
                       "  30 4 N-BK7 12 1 conic=-0.5 asph=1e-06,-2e-09 coating=stack(MgF2:0.25,ZrO2:0.5)@500\n"
                       "  -50 2,8 air 12 1\n  20 3 1.6 40 9 1 stop\n  45 1 N-BK7 9 1 conic=-0.3 biconic=-70,0.25\n"
                       "  0 1 air 9 1\n  -40 auto 1 0 9 2 cyl_x 30\n";
    const Lens a = parseLensText(text, "x.lens");
    const Lens b = parseLensText(writeLensText(a), "y.lens");
    expectSamePrescription(a, b, "extensions");
    EXPECT_EQ(b.surfaces[5].radiusY, 30.0);
    EXPECT_EQ(b.surfaces[3].shape, SurfaceShape::Biconic);
    EXPECT_EQ(b.surfaces[3].radiusX, -70.0);
    EXPECT_EQ(b.surfaces[3].conicX, 0.25);
}

// Graded media: every coefficient and its dispersion, to the last bit.
TEST(LensWriter, GradientsRoundTrip) {
    const char* text = "name: g\nsurfaces:\n"
                       "  0 5 1.6 40 4 1 grin_r=-0.0021:1.5e-05,3.3e-07:0 grin_z=0.0013:-2e-06\n"
                       "  0 2 air 4 1 stop\n  20 3 1.6 40 9 1 grin_z=0.001:0\n  -40 30 1 0 9\n";
    const Lens a = parseLensText(text, "g.lens");
    ASSERT_TRUE(a.surfaces[0].medium.gradient);
    EXPECT_EQ(a.surfaces[0].medium.gradient->radial.size(), 2u);
    const Lens b = parseLensText(writeLensText(a), "h.lens");
    expectSamePrescription(a, b, "gradients");
}

// `lens convert` of a .zmx GRADIENT3 surface (inches) writes the coefficients, in mm, that read back.
TEST(LensWriter, ZmxGradientsConvertToTheLensFormat) {
    const std::string zmx = "UNIT IN\nSURF 0\n DISZ INFINITY\nSURF 1\n TYPE GRADIENT3\n STOP\n CURV 0.05\n DISZ 0.25\n"
                            " PARM 2 1.6\n PARM 3 -0.01\n PARM 5 -3e-6\n PARM 6 0.02\n DIAM 0.3\n"
                            "SURF 2\n CURV -0.02\n DISZ 2\n DIAM 0.3\nSURF 3\n";
    const Lens a = importZmx(zmx, "g3.zmx");
    ASSERT_TRUE(a.surfaces[0].medium.gradient);
    const Lens b = parseLensText(writeLensText(a), "g3.lens");
    expectSamePrescription(a, b, "zmx gradient");
    EXPECT_EQ(b.surfaces[0].medium.index(400.0), 1.6);
    EXPECT_EQ(paraxialEfl(a, lines::d), paraxialEfl(b, lines::d));
}
