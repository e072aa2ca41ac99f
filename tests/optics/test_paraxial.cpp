#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/paraxial.h"
#include "optics/real_ray.h"
#include "optics/zoom.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_support.h"

using namespace ff;
using namespace ff::optics;

namespace {

struct Oracle {
    const char* file;
    std::size_t zoom;
    double efl, bfd;
};

// Paraxial values at the d line from ../shared/reference/lenses.md, computed there independently
// from the same tables. EFL to 0.01 %, BFD to 0.01 mm.
const Oracle kOracles[] = {
    {"cooke-triplet-50mm-f5.lens", 0, 50.0213, 42.4364}, {"double-gauss-50mm-f2.lens", 0, 50.3582, 36.1059},
    {"tessar-100mm-f3.5.lens", 0, 100.0000, 85.2440},    {"double-gauss-100mm-f2.lens", 0, 100.004, 61.488},
    {"telephoto-127mm-f5.6.lens", 0, 127.016, 63.406},   {"wide-angle-16.7mm-f4.lens", 0, 16.669, 39.761},
    {"zoom-70-200mm-f2.8.lens", 0, 72.12, 52.446},       {"zoom-70-200mm-f2.8.lens", 1, 134.95, 52.429},
    {"zoom-70-200mm-f2.8.lens", 2, 193.91, 52.421},      {"nikon-28-75mm-at-28mm.lens", 0, 28.90, 39.68},
};

} // namespace

TEST(Paraxial, BundledLensesMatchPublishedFirstOrderData) {
    for (const Oracle& o : kOracles) {
        const Lens lens = atZoom(loadLens(test::lensPath(o.file)), o.zoom);
        const FirstOrder f = analyzeFirstOrder(lens, lines::d);
        EXPECT_NEAR(f.efl, o.efl, 1e-4 * o.efl) << o.file << " zoom " << o.zoom;
        EXPECT_NEAR(f.bfd, o.bfd, 0.01) << o.file << " zoom " << o.zoom;
    }
}

TEST(Paraxial, BundledLensesMatchPublishedPupilsAndFNumbers) {
    // lenses.md: Cooke EP 11.5058 behind vertex 1, EPD 10.0001, f/5.002; double Gauss 50 EP 19.9465,
    // EPD 24.8051, f/2.030; Tessar EP 19.8068, EPD 28.9842, f/3.450; telephoto EPD 22.681;
    // wide angle EPD 4.167, f/4.00.
    const auto cooke = analyzeFirstOrder(loadLens(test::lensPath("cooke-triplet-50mm-f5.lens")), lines::d);
    EXPECT_NEAR(cooke.entrancePupilZ, 11.5058, 1e-3);
    EXPECT_NEAR(cooke.entrancePupilDiameter, 10.0001, 1e-3);
    EXPECT_NEAR(cooke.fNumber, 5.002, 1e-3);
    const auto dg = analyzeFirstOrder(loadLens(test::lensPath("double-gauss-50mm-f2.lens")), lines::d);
    EXPECT_NEAR(dg.entrancePupilZ, 19.9465, 1e-3);
    EXPECT_NEAR(dg.entrancePupilDiameter, 24.8051, 1e-3);
    EXPECT_NEAR(dg.fNumber, 2.030, 1e-3);
    const auto tessar = analyzeFirstOrder(loadLens(test::lensPath("tessar-100mm-f3.5.lens")), lines::d);
    EXPECT_NEAR(tessar.entrancePupilZ, 19.8068, 1e-3);
    EXPECT_NEAR(tessar.entrancePupilDiameter, 28.9842, 1e-3);
    const auto tele = analyzeFirstOrder(loadLens(test::lensPath("telephoto-127mm-f5.6.lens")), lines::d);
    EXPECT_NEAR(tele.entrancePupilDiameter, 22.681, 2e-3);
    const auto wide = analyzeFirstOrder(loadLens(test::lensPath("wide-angle-16.7mm-f4.lens")), lines::d);
    EXPECT_NEAR(wide.entrancePupilDiameter, 4.167, 2e-3);
    EXPECT_NEAR(wide.fNumber, 4.00, 5e-3);
}

TEST(Paraxial, RealRayFocalLengthAgreesForEveryBundledLens) {
    // A real ray at 1e-4 of the entrance-pupil radius sees the paraxial EFL up to O(h^2)
    // aberrations: relative agreement 1e-6.
    for (const auto& entry : std::filesystem::directory_iterator(test::sourceDir() / "lenses")) {
        if (entry.path().extension() != ".lens") continue;
        const Lens base = loadLens(entry.path());
        for (std::size_t k = 0; k < base.zoomCount(); ++k) {
            const Lens lens = atZoom(base, k);
            for (double lambda : {lines::F, lines::d, lines::C}) {
                const FirstOrder f = analyzeFirstOrder(lens, lambda);
                const double real = realRayEfl(lens, lambda, 1e-4 * 0.5 * f.entrancePupilDiameter);
                EXPECT_NEAR(real / f.efl, 1.0, 1e-6)
                    << entry.path().filename() << " zoom " << k << " at " << lambda << " nm";
            }
        }
    }
}

namespace {

Lens singlet(double r1, double r2, double n, double thickness) {
    const std::string text = "surfaces:\n  stop 0 1 0 5\n  " + std::to_string(r1) + " " + std::to_string(thickness) +
                             " " + std::to_string(n) + " 0 10\n  " + std::to_string(r2) + " auto 1 0 10\n";
    return parseLensText(text, "singlet.lens");
}

} // namespace

TEST(Paraxial, ThinSingletFollowsLensmakersEquation) {
    // 1/f = (n - 1)(1/R1 - 1/R2) for a lens of negligible thickness.
    const double r1 = 60.0, r2 = -90.0, n = 1.5;
    const double f = 1.0 / ((n - 1.0) * (1.0 / r1 - 1.0 / r2));
    const FirstOrder fo = analyzeFirstOrder(singlet(r1, r2, n, 0.0), lines::d);
    EXPECT_NEAR(fo.efl, f, 1e-9 * f);
    EXPECT_NEAR(fo.bfd, f, 1e-9 * f);
    EXPECT_NEAR(fo.ffd, f, 1e-9 * f);
}

TEST(Paraxial, ThickSingletFollowsThickLensFormula) {
    // 1/f = (n - 1)[1/R1 - 1/R2 + (n - 1) d / (n R1 R2)];  BFD = f (1 - (n - 1) d / (n R1));
    // FFD = f (1 + (n - 1) d / (n R2)).
    const double r1 = 40.0, r2 = -25.0, n = 1.7, d = 8.0;
    const double f = 1.0 / ((n - 1.0) * (1.0 / r1 - 1.0 / r2 + (n - 1.0) * d / (n * r1 * r2)));
    const double bfd = f * (1.0 - (n - 1.0) * d / (n * r1));
    const double ffd = f * (1.0 + (n - 1.0) * d / (n * r2));
    const Lens lens = singlet(r1, r2, n, d);
    const FirstOrder fo = analyzeFirstOrder(lens, lines::d);
    EXPECT_NEAR(fo.efl, f, 1e-9 * f);
    EXPECT_NEAR(fo.bfd, bfd, 1e-9 * f);
    EXPECT_NEAR(fo.ffd, ffd, 1e-9 * f);
    EXPECT_NEAR(lens.surfaces.back().thickness, bfd, 1e-9 * f); // 'auto' = paraxial focus
}

TEST(Paraxial, PupilsAreImagesOfTheStop) {
    // Thin lens f = 100 (R = +-100, n = 1.5, zero thickness) with the stop s = 20 mm behind it.
    // Seen from the front, the stop is imaged by the lens: virtual image at s f / (f - s) = 25 mm
    // behind the lens, magnification f / (f - s) = 1.25, so EPD = 1.25 x 10 = 12.5 mm. The exit
    // pupil is the stop itself (nothing behind it).
    const Lens behind = parseLensText("surfaces:\n  100 0 1.5 0 20\n  -100 20 1 0 20\n  stop auto 1 0 5\n", "a.lens");
    const FirstOrder a = analyzeFirstOrder(behind, lines::d);
    EXPECT_NEAR(a.efl, 100.0, 1e-9);
    EXPECT_NEAR(a.entrancePupilZ, 25.0, 1e-9);
    EXPECT_NEAR(a.entrancePupilDiameter, 12.5, 1e-9);
    EXPECT_NEAR(a.exitPupilZ, 0.0, 1e-9);
    EXPECT_NEAR(a.exitPupilDiameter, 10.0, 1e-9);
    EXPECT_NEAR(a.fNumber, 8.0, 1e-9);

    // The mirror case: stop 20 mm in front of the lens. Now the entrance pupil is the stop, at
    // z = 0, and the exit pupil is its image, 25 mm in front of the lens (z = -25), 12.5 mm wide.
    const Lens front = parseLensText("surfaces:\n  stop 20 1 0 5\n  100 0 1.5 0 20\n  -100 auto 1 0 20\n", "b.lens");
    const FirstOrder b = analyzeFirstOrder(front, lines::d);
    EXPECT_NEAR(b.entrancePupilZ, 0.0, 1e-12);
    EXPECT_NEAR(b.entrancePupilDiameter, 10.0, 1e-12);
    EXPECT_NEAR(b.exitPupilZ, -25.0, 1e-9);
    EXPECT_NEAR(b.exitPupilDiameter, 12.5, 1e-9);
}

TEST(Paraxial, GhostCountIsPairsOfReflectingInterfaces) {
    // Double Gauss 50: 11 surfaces, the flat air-air stop does not reflect: m = 10, m(m-1)/2 = 45.
    const FirstOrder f = analyzeFirstOrder(loadLens(test::lensPath("double-gauss-50mm-f2.lens")), lines::d);
    EXPECT_EQ(f.reflectingInterfaces, 10u);
    EXPECT_EQ(f.ghostCount, 45u);
    // Cooke: 6 glass-air surfaces; the stop is ON surface 4, a real interface that reflects.
    const FirstOrder c = analyzeFirstOrder(loadLens(test::lensPath("cooke-triplet-50mm-f5.lens")), lines::d);
    EXPECT_EQ(c.reflectingInterfaces, 6u);
    EXPECT_EQ(c.ghostCount, 15u);
}

TEST(Paraxial, FNumberHeaderSetsTheStopAndIsClampedByIt) {
    // Thin lens f = 100 with its stop in contact: EPD = 2 r, so f/4 needs r = 12.5 mm.
    const char* base = "surfaces:\n  stop 0 1 0 %s\n  100 0 1.5 0 30\n  -100 auto 1 0 30\n";
    char text[256];
    std::snprintf(text, sizeof text, base, "0");
    Lens set = parseLensText(std::string("f_number: 4\n") + text, "f.lens");
    EXPECT_NEAR(analyzeFirstOrder(set, lines::d).stopSemiAperture, 12.5, 1e-9);
    std::snprintf(text, sizeof text, base, "10");
    CollectingReporter rep;
    Lens clamped = parseLensText(std::string("f_number: 4\n") + text, "f.lens", &rep);
    EXPECT_NEAR(analyzeFirstOrder(clamped, lines::d).stopSemiAperture, 10.0, 1e-12);
    ASSERT_FALSE(rep.diagnostics.empty());
    EXPECT_EQ(rep.diagnostics.back().severity, Severity::Warning);
    EXPECT_EQ(rep.diagnostics.back().str(), "f.lens:3:3: f_number 4 needs a larger opening than the stop's "
                                            "semi-aperture 10 mm; clamping the aperture to the stop");
}
