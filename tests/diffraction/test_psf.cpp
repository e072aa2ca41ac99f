// The PSF against Fraunhofer diffraction's closed forms, derived here: the Airy pattern of a circular
// pupil (first dark ring, encircled energy, peak irradiance, pixel integrals by quadrature), the spikes
// of an N-blade iris, and the energy and symmetry of the binned RGB kernel.

#include "diffraction/convolution.h"
#include "diffraction/psf.h"
#include "optics/lens_loader.h"
#include "optics/paraxial.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ff::diffraction {
namespace {

constexpr double kPi = std::numbers::pi;

// The first zero of J1 (bisection on std::cyl_bessel_j): 3.8317...
double firstZeroOfJ1() {
    double a = 3.0, b = 4.5;
    for (int i = 0; i < 100; ++i) {
        const double m = 0.5 * (a + b);
        (std::cyl_bessel_j(1.0, a) * std::cyl_bessel_j(1.0, m) <= 0.0 ? b : a) = m;
    }
    return 0.5 * (a + b);
}

// Airy irradiance per unit flux at r (mm) for lambda N (mm): I0 (2 J1(v) / v)^2, v = pi r / (lambda N),
// I0 = pi / (4 (lambda N)^2) (the peak pi D^2 / (4 lambda^2 f^2) per unit flux).
double airy(double r, double lambdaN) {
    const double I0 = kPi / (4.0 * lambdaN * lambdaN);
    const double v = kPi * r / lambdaN;
    if (v < 1e-9) return I0;
    const double a = 2.0 * std::cyl_bessel_j(1.0, v) / v;
    return I0 * a * a;
}

double at(const SampledPsf& p, int dx, int dy) {
    return p.value[static_cast<std::size_t>(p.size / 2 + dy) * p.size + (p.size / 2 + dx)];
}

TEST(Psf, CircularPupilGivesTheAiryPattern) {
    const Aperture a{0, 0.0, 8.0};
    const double lambda = 550.0, lambdaN = lambda * 1e-6 * a.fNumber, spacing = lambdaN / 8.0;
    const SampledPsf p = sampledPsf(a, lambda, spacing, 1024);
    double total = 0.0;
    for (double v : p.value) total += v;
    EXPECT_NEAR(total, 1.0, 1e-6);
    // Peak irradiance: the centre sample over its area.
    EXPECT_NEAR(at(p, 0, 0) / (spacing * spacing) / airy(0.0, lambdaN), 1.0, 0.01);
    // First dark ring: the first minimum along +x (and +y) within a sample of 1.2197 lambda N.
    const double ring = firstZeroOfJ1() / kPi * lambdaN;
    for (int axis = 0; axis < 2; ++axis) {
        int k = 1;
        while (at(p, axis ? 0 : k + 1, axis ? k + 1 : 0) < at(p, axis ? 0 : k, axis ? k : 0)) ++k;
        EXPECT_NEAR(k * spacing, ring, spacing) << "axis " << axis;
    }
    // Encircled energy within the first ring: 1 - J0(3.8317)^2 = 0.838.
    const double expected = 1.0 - std::pow(std::cyl_bessel_j(0.0, firstZeroOfJ1()), 2);
    double inside = 0.0;
    const int reach = static_cast<int>(ring / spacing) + 2;
    for (int y = -reach; y <= reach; ++y)
        for (int x = -reach; x <= reach; ++x)
            if (std::hypot(x, y) * spacing <= ring) inside += at(p, x, y);
    EXPECT_NEAR(inside, expected, 0.005);
    EXPECT_NEAR(expected, 0.838, 0.001);
    // The profile: within 1 % of the peak out to the third ring.
    for (int k = 0; k < 80; ++k)
        EXPECT_NEAR(at(p, k, 0) / (spacing * spacing), airy(k * spacing, lambdaN), 0.01 * airy(0.0, lambdaN)) << k;
}

// Directions (rad, from +x towards +y) in which the PSF's energy between radii r0 and r1 (samples) is
// a local maximum over `share` of the brightest direction's: the PSF summed along each ray, bilinear
// between samples (the sum smooths the rings a circle would cross).
std::vector<double> spikes(const SampledPsf& p, double r0, double r1, double share) {
    const int n = 1440;
    std::vector<double> v(n, 0.0);
    for (int i = 0; i < n; ++i)
        for (double r = r0; r <= r1; r += 0.5) {
            const double t = 2.0 * kPi * i / n, x = r * std::cos(t), y = r * std::sin(t);
            const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
            const double fx = x - x0, fy = y - y0;
            v[i] += (1 - fx) * (1 - fy) * at(p, x0, y0) + fx * (1 - fy) * at(p, x0 + 1, y0) +
                    (1 - fx) * fy * at(p, x0, y0 + 1) + fx * fy * at(p, x0 + 1, y0 + 1);
        }
    const double top = *std::max_element(v.begin(), v.end());
    std::vector<double> out;
    for (int i = 0; i < n; ++i)
        if (v[i] > share * top && v[i] >= v[(i + n - 1) % n] && v[i] > v[(i + 1) % n]) out.push_back(2.0 * kPi * i / n);
    return out;
}

// The angular distance between two directions, in [0, pi].
double angleBetween(double a, double b) {
    const double d = std::fmod(std::abs(a - b), 2.0 * kPi);
    return std::min(d, 2.0 * kPi - d);
}

// A straight edge diffracts light along its normal, both ways: an N-blade iris has spikes at the blades'
// normals, rotation + (k + 1/2) 2 pi / N, and opposite them: 2N for odd N, N for even N (the opposite
// normals coincide).
TEST(Psf, BladesGiveSpikesAlongTheirNormals) {
    for (int blades : {5, 6, 7, 8}) {
        SCOPED_TRACE(std::to_string(blades) + " blades");
        const double rotation = 10.0 * kPi / 180.0;
        const Aperture a{blades, rotation, 8.0};
        const double lambdaN = 550e-6 * a.fNumber;
        const SampledPsf p = sampledPsf(a, 550.0, lambdaN / 4.0, 1024);
        const auto found = spikes(p, 100.0, 400.0, 0.1); // 25 to 100 lambda N out
        const std::size_t expected =
            blades % 2 ? 2 * static_cast<std::size_t>(blades) : static_cast<std::size_t>(blades);
        ASSERT_EQ(found.size(), expected);
        for (double t : found) {
            double nearest = kPi;
            for (int k = 0; k < 2 * blades; ++k)
                nearest =
                    std::min(nearest, angleBetween(t, rotation + (k / 2 + 0.5) * 2.0 * kPi / blades + (k % 2) * kPi));
            EXPECT_LT(nearest, 1.0 * kPi / 180.0) << t * 180.0 / kPi;
        }
    }
}

// A defocus W020 (u^2 + v^2) moves each ray by the transverse aberration -(R / r_p) dW/du, R = N D the
// distance to the sensor and r_p = D / 2: the rays spread over a disc of radius r = 4 N W020. For defocus of many waves
// the PSF tends to that uniform disc, whose half-energy radius is r / sqrt(2); it grows in proportion to W020.
TEST(Psf, DefocusSpreadsTheLightOverTheGeometricBlurDisc) {
    const Aperture a{0, 0.0, 8.0};
    const double lambda = 550.0, lambdaN = lambda * 1e-6 * a.fNumber, spacing = lambdaN / 4.0;
    std::vector<double> halfEnergy;
    for (double waves : {10.0, 20.0}) {
        const double w020 = waves * lambda * 1e-6; // mm
        const SampledPsf p =
            sampledPsf(a, lambda, spacing, 1024, [w020](double u, double v) { return w020 * (u * u + v * v); });
        // The radius holding half the flux, from the samples sorted by radius.
        std::vector<std::pair<double, double>> byRadius;
        for (int y = -p.size / 2; y < p.size / 2; ++y)
            for (int x = -p.size / 2; x < p.size / 2; ++x)
                byRadius.push_back({std::hypot(x, y) * spacing, at(p, x, y)});
        std::sort(byRadius.begin(), byRadius.end());
        double sum = 0.0, r50 = 0.0;
        for (const auto& [r, v] : byRadius)
            if ((sum += v) >= 0.5) {
                r50 = r;
                break;
            }
        const double geometric = 4.0 * a.fNumber * w020;
        EXPECT_NEAR(r50 / (geometric / std::sqrt(2.0)), 1.0, 0.05) << waves << " waves";
        halfEnergy.push_back(r50);
    }
    EXPECT_NEAR(halfEnergy[1] / halfEnergy[0], 2.0, 0.1);
}

TEST(Psf, RefusesSamplingsThatCannotHoldThePupil) {
    const Aperture a{0, 0.0, 4.0};
    const double lambdaN = 550e-6 * 4.0;
    EXPECT_THROW(sampledPsf(a, 550.0, lambdaN * 0.6, 512), Error);    // 307 samples > 256: would alias
    EXPECT_THROW(sampledPsf(a, 550.0, lambdaN / 32.0, 512), Error);   // 16 samples across the pupil
    EXPECT_THROW(sampledPsf(a, 550.0, lambdaN / 4.0, 100000), Error); // too large a transform
}

// Binned over pixels: each pixel holds the integral of the Airy irradiance over its square (by a
// 400 x 400 midpoint quadrature here), the light at the centre of its pixel.
TEST(Psf, PixelsHoldTheIntegralOfTheIrradianceOverThem) {
    const Aperture a{0, 0.0, 8.0};
    const double lambdaN = 550e-6 * 8.0;
    PsfSettings s;
    s.wavelengthsNm = {550.0};
    s.pitchMm = 1.5 * lambdaN; // the core spans a few pixels
    const Psf psf = pixelPsf(a, s);
    ASSERT_GT(psf.radius, 20);
    for (auto [dx, dy] : std::initializer_list<std::pair<int, int>>{{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 0}, {3, 2}}) {
        const int n = 400;
        double sum = 0.0;
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double x = (dx - 0.5 + (i + 0.5) / n) * s.pitchMm, y = (dy - 0.5 + (j + 0.5) / n) * s.pitchMm;
                sum += airy(std::hypot(x, y), lambdaN);
            }
        const double expected = sum * s.pitchMm * s.pitchMm / (double(n) * n);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(psf.at(c, dx, dy), expected, 0.01 * expected + 1e-5) << dx << "," << dy << " channel " << c;
    }
}

// The RGB kernel carries the light's flux in every channel (with its far field: 14 spikes of
// L beta / (4 pi^2 A r^2) per pixel leave about 5e-5 beyond 2 000 px), stays centred (symmetric through the
// light's pixel: |P^|^2 of a real pupil is), and spreads red wider than blue (the pattern scales with
// lambda).
TEST(Psf, RgbKernelIsCentredAndCarriesTheFlux) {
    const Aperture a{7, 0.3, 11.0};
    PsfSettings s;
    s.pitchMm = 0.0125;
    const Psf psf = pixelPsf(a, s);
    EXPECT_EQ(psf.wavelengthsNm.size(), 8u);
    const int R = psf.radius;
    std::array<double, 3> spread{};
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0, peak = 0.0, moment = 0.0;
        for (int dy = -R; dy <= R; ++dy)
            for (int dx = -R; dx <= R; ++dx) {
                const double v = psf.at(c, dx, dy);
                sum += v;
                peak = std::max(peak, v);
                moment += v * std::min(double(dx * dx + dy * dy), 100.0);
                EXPECT_NEAR(v, psf.at(c, -dx, -dy), 1e-6 * psf.at(c, 0, 0));
            }
        double whole = 0.0;
        for (float v : frameKernel(psf, c, 2000, 2000)) whole += v;
        EXPECT_NEAR(whole, 1.0, 2e-4) << c;
        EXPECT_LT(sum, whole) << c;
        EXPECT_EQ(peak, psf.at(c, 0, 0)) << c;
        spread[static_cast<std::size_t>(c)] = moment;
    }
    EXPECT_GT(spread[0], spread[1]);
    EXPECT_GT(spread[1], spread[2]);
    EXPECT_LT(psf.outside, 2e-3);
}

// The lens's aperture: an image-space working f-number from the exit pupil equals EFL / entrance pupil
// diameter for a lens focused at infinity (paraxially, both are 1 / (2 u')).
TEST(Psf, ApertureOfALensFocusedAtInfinity) {
    optics::Lens lens = optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/double-gauss-50mm-f2.lens");
    optics::focusAtParaxialImage(lens);
    const Aperture a = apertureOf(lens);
    EXPECT_NEAR(a.fNumber / optics::analyzeFirstOrder(lens, 587.56).fNumber, 1.0, 1e-6);
}

// A front anamorphic attachment sits in front of the stop: the exit pupil and the image-space cone
// are the prime's in both sections, so the sensor's PSF is the prime's (lenses/anamorphic-2x-...lens
// is that attachment before double-gauss-50mm-f2.lens, read here from its own file). A cylinder
// behind the stop changes the cone in one section only: its PSF would be elliptical, and is refused.
TEST(Psf, AFrontAnamorphicHasItsPrimesApertureAndARearCylinderIsRefused) {
    const Aperture prime =
        apertureOf(optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/double-gauss-50mm-f2.lens"));
    const Aperture anamorphic =
        apertureOf(optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/anamorphic-2x-double-gauss-50mm.lens"));
    EXPECT_NEAR(anamorphic.fNumber, prime.fNumber, 1e-9 * prime.fNumber);
    EXPECT_EQ(anamorphic.blades, prime.blades);
    const optics::Lens rear = optics::parseLensBytes("name: rear cylinder\nsurfaces:\n"
                                                     "  stop 10 1.0 0 5 0\n"
                                                     "  0 5 1.5 0 12 0\n"
                                                     "  -60 50 1.0 0 12 0 biconic=-30\n",
                                                     "lens", "rear.lens");
    EXPECT_THROW(apertureOf(rear), Error);
}

} // namespace
} // namespace ff::diffraction
