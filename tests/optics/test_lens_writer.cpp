#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/lens_writer.h"
#include "optics/paraxial.h"

#include <gtest/gtest.h>

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
                       "  -50 2,8 air 12 1\n  20 3 1.6 40 9 1 stop\n  -40 auto 1 0 9 2 cyl_x 30\n";
    const Lens a = parseLensText(text, "x.lens");
    const Lens b = parseLensText(writeLensText(a), "y.lens");
    expectSamePrescription(a, b, "extensions");
    EXPECT_EQ(b.surfaces[3].radiusY, 30.0);
}
