#include "optics/glass_catalog.h"
#include "optics/lens_loader.h"
#include "optics/thin_film.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <tuple>

#include "test_support.h"

using namespace ff::optics;

namespace {

double nOf(const char* glass, double lambdaNm) {
    return GlassCatalog::builtin().find(glass)->dispersion.index(lambdaNm);
}

} // namespace

TEST(Fresnel, NormalIncidenceIsTheSquaredIndexRatio) {
    // ((n1 - n2) / (n1 + n2))^2: n = 1.67 in air gives 0.0630; the same from either side.
    const double r = (1.67 - 1.0) / (1.67 + 1.0);
    EXPECT_NEAR(fresnelReflectance(1.0, 1.67, 1.0), r * r, 1e-15);
    EXPECT_NEAR(fresnelReflectance(1.67, 1.0, 1.0), r * r, 1e-15);
    EXPECT_NEAR(r * r, 0.0630, 5e-5);
}

TEST(Fresnel, BrewsterAngleLeavesOnlyTheSPart) {
    // At tan(theta_B) = n2/n1, Rp = 0, so R = Rs/2 with rs = (cos_i - n cos_t)/(cos_i + n cos_t), theta_t = 90 -
    // theta_B.
    const double n = 1.5, thetaB = std::atan(n);
    const double cosI = std::cos(thetaB), cosT = std::sin(thetaB);
    const double rs = (cosI - n * cosT) / (cosI + n * cosT);
    EXPECT_NEAR(fresnelReflectance(1.0, n, cosI), 0.5 * rs * rs, 1e-15);
}

TEST(Fresnel, TotalInternalReflectionBeyondTheCriticalAngle) {
    const double critical = std::asin(1.0 / 1.5);
    EXPECT_EQ(fresnelReflectance(1.5, 1.0, std::cos(critical + 0.01)), 1.0);
    EXPECT_LT(fresnelReflectance(1.5, 1.0, std::cos(critical - 0.01)), 1.0);
    EXPECT_EQ(filmReflectance(1.5, {{1.38, 99.64}}, 1.0, std::cos(critical + 0.01), 550.0), 1.0);
}

TEST(ThinFilm, EmptyStackIsTheBareInterface) {
    for (double c : {1.0, 0.8, 0.3})
        EXPECT_NEAR(filmReflectance(1.0, {}, 1.52, c, 550.0), fresnelReflectance(1.0, 1.52, c), 1e-15);
    // A layer of the substrate's own index changes nothing, whatever its thickness.
    EXPECT_NEAR(filmReflectance(1.0, {{1.52, 123.0}}, 1.52, 0.7, 500.0), fresnelReflectance(1.0, 1.52, 0.7), 1e-14);
}

TEST(ThinFilm, QuarterWaveAtItsDesignWavelength) {
    // R(lambda0, 0 deg) = ((n0 n2 - n1^2) / (n0 n2 + n1^2))^2 for d = lambda0 / (4 n1).
    const double n1 = 1.38, n2 = 1.52, d = 550.0 / (4.0 * n1);
    const double r = (n2 - n1 * n1) / (n2 + n1 * n1);
    EXPECT_NEAR(filmReflectance(1.0, {{n1, d}}, n2, 1.0, 550.0), r * r, 1e-14);
}

TEST(ThinFilm, MatchesTheReferenceTable) {
    // optics.md, exact matrix method, unpolarised, MgF2 n = 1.38, d = 99.64 nm, values in percent.
    struct Row {
        double lambda, bk7, bk7Coated, sf11, sf11Coated, bk7Coated45;
    };
    const Row rows[] = {{400, 4.400, 2.198, 8.828, 2.918, 2.109}, {450, 4.327, 1.595, 8.443, 1.113, 1.874},
                        {500, 4.276, 1.326, 8.201, 0.291, 1.911}, {550, 4.239, 1.271, 8.034, 0.094, 2.081},
                        {600, 4.210, 1.339, 7.914, 0.253, 2.304}, {650, 4.187, 1.470, 7.823, 0.596, 2.539},
                        {700, 4.168, 1.631, 7.753, 1.022, 2.766}};
    const std::vector<FilmLayer> mgf2 = {{1.38, 99.64}};
    const double cos45 = std::sqrt(0.5);
    for (const Row& r : rows) {
        const double bk7 = nOf("N-BK7", r.lambda), sf11 = nOf("N-SF11", r.lambda);
        EXPECT_NEAR(100.0 * filmReflectance(1.0, {}, bk7, 1.0, r.lambda), r.bk7, 6e-4) << r.lambda;
        EXPECT_NEAR(100.0 * filmReflectance(1.0, mgf2, bk7, 1.0, r.lambda), r.bk7Coated, 6e-4) << r.lambda;
        EXPECT_NEAR(100.0 * filmReflectance(1.0, {}, sf11, 1.0, r.lambda), r.sf11, 6e-4) << r.lambda;
        EXPECT_NEAR(100.0 * filmReflectance(1.0, mgf2, sf11, 1.0, r.lambda), r.sf11Coated, 6e-4) << r.lambda;
        EXPECT_NEAR(100.0 * filmReflectance(1.0, mgf2, bk7, cos45, r.lambda), r.bk7Coated45, 6e-4) << r.lambda;
    }
}

TEST(ThinFilm, BroadbandStackHasTheWShapedCurve) {
    // optics.md: MgF2 l/4 / ZrO2 l/2 / Al2O3 l/4 at 550 nm (n 1.38 / 2.05 / 1.63) on N-BK7:
    // R = 4.0 (400), 0.21 (450), 0.09 (500), 0.18 (550), 0.11 (600), 0.03 (650), 0.16 (700) percent.
    const std::vector<FilmLayer> stack = {
        {1.38, 550.0 / (4 * 1.38)}, {2.05, 550.0 / (2 * 2.05)}, {1.63, 550.0 / (4 * 1.63)}};
    const std::pair<double, double> expected[] = {{400, 4.0},  {450, 0.21}, {500, 0.09}, {550, 0.18},
                                                  {600, 0.11}, {650, 0.03}, {700, 0.16}};
    for (const auto& [lambda, percent] : expected) {
        const double tol = lambda == 400 ? 0.06 : 0.006; // printed to 1 or 2 decimals
        EXPECT_NEAR(100.0 * filmReflectance(1.0, stack, nOf("N-BK7", lambda), 1.0, lambda), percent, tol) << lambda;
    }
}

TEST(ThinFilm, CoatingSpecsResolveThroughTheMaterialCatalogue) {
    // Quarter wave of the catalogue's (dispersive) MgF2: d = 0.25 * 550 / n(550).
    const auto layers = filmLayers(CoatingSpec::mgf2(550.0), 550.0);
    ASSERT_EQ(layers.size(), 1u);
    EXPECT_NEAR(layers[0].thicknessNm * layers[0].n, 137.5, 1e-12);
    // Light from the glass side meets the stack reversed; for a single layer the two are the same
    // reflectance at normal incidence (reciprocity of a lossless stack).
    const CoatingSpec bb = CoatingSpec::broadband();
    const double nG = nOf("N-BK7", 500.0);
    EXPECT_NEAR(coatedReflectance(bb, 1.0, nG, 1.0, 500.0), coatedReflectance(bb, nG, 1.0, 1.0, 500.0), 1e-12);
    EXPECT_NEAR(coatedReflectance(CoatingSpec::none(), 1.0, nG, 1.0, 500.0), fresnelReflectance(1.0, nG, 1.0), 1e-15);
}

TEST(Fresnel, ReflectedAndTransmittedPowerAddUpToOne) {
    // T from the Fresnel transmission coefficients, written out here independently:
    // ts = 2 n1 ci / (n1 ci + n2 ct), tp = 2 n1 ci / (n2 ci + n1 ct), T = (n2 ct / n1 ci)(ts^2 + tp^2)/2.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> idx(1.0, 2.2), cosd(0.05, 1.0);
    for (int k = 0; k < 1000; ++k) {
        const double n1 = idx(rng), n2 = idx(rng), ci = cosd(rng);
        const double st = n1 / n2 * std::sqrt(1.0 - ci * ci);
        if (st >= 1.0) {
            EXPECT_EQ(fresnelReflectance(n1, n2, ci), 1.0);
            continue;
        }
        const double ct = std::sqrt(1.0 - st * st);
        const double ts = 2 * n1 * ci / (n1 * ci + n2 * ct), tp = 2 * n1 * ci / (n2 * ci + n1 * ct);
        const double T = (n2 * ct) / (n1 * ci) * 0.5 * (ts * ts + tp * tp);
        EXPECT_NEAR(fresnelReflectance(n1, n2, ci) + T, 1.0, 1e-12) << n1 << " " << n2 << " " << ci;
    }
}

TEST(ThinFilm, SingleLayerMatchesAirysFormulaAndConservesEnergy) {
    // Airy summation for one film with tilted admittances eta = n cos (s) or n / cos (p):
    //   r = (r01 + r12 e^{-2i d}) / (1 + r01 r12 e^{-2i d}),  t = t01 t12 e^{-i d} / (1 + r01 r12 e^{-2i d}),
    //   r_ij = (eta_i - eta_j)/(eta_i + eta_j), t_ij = 2 eta_i / (eta_i + eta_j), T = (eta_2 / eta_0) |t|^2.
    // The matrix code must give R = |r|^2 (averaged), and R + T = 1.
    using cplx = std::complex<double>;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> sub(1.45, 1.95), film(1.3, 2.3), thick(20.0, 400.0), cosd(0.5, 1.0),
        lam(400.0, 700.0);
    for (int k = 0; k < 500; ++k) {
        const double n0 = 1.0, n1 = film(rng), n2 = sub(rng), d = thick(rng), ci = cosd(rng), l = lam(rng);
        const double s0 = std::sqrt(1.0 - ci * ci);
        const double c1 = std::sqrt(1.0 - std::pow(n0 * s0 / n1, 2)), c2 = std::sqrt(1.0 - std::pow(n0 * s0 / n2, 2));
        const double delta = 2.0 * std::numbers::pi * n1 * d * c1 / l;
        double Rsum = 0.0, Tsum = 0.0;
        for (bool p : {false, true}) {
            const double e0 = p ? n0 / ci : n0 * ci, e1 = p ? n1 / c1 : n1 * c1, e2 = p ? n2 / c2 : n2 * c2;
            const double r01 = (e0 - e1) / (e0 + e1), r12 = (e1 - e2) / (e1 + e2);
            const double t01 = 2 * e0 / (e0 + e1), t12 = 2 * e1 / (e1 + e2);
            const cplx ph = std::exp(cplx(0.0, -2.0 * delta));
            const cplx r = (r01 + r12 * ph) / (1.0 + r01 * r12 * ph);
            const cplx t = t01 * t12 * std::exp(cplx(0.0, -delta)) / (1.0 + r01 * r12 * ph);
            Rsum += 0.5 * std::norm(r);
            Tsum += 0.5 * e2 / e0 * std::norm(t);
        }
        EXPECT_NEAR(Rsum + Tsum, 1.0, 1e-12);
        EXPECT_NEAR(filmReflectance(n0, {{n1, d}}, n2, ci, l), Rsum, 1e-12);
    }
}

// The tabulated reflectance against the exact one it tabulates, for every coated surface of every
// bundled lens, from both sides, at the table's three wavelengths: at 5 000 random incidences and
// at the critical angle's neighbourhood, where the square-root branch point is. Asked: 1e-8 absolute,
// a thousandth of the 16-bit step the table stores a ghost's weight to (its range / 65534, over
// reflectances of 0.2-5 % each), and the Hermite pieces' error is fourth order in the interval
// (1/1024 of the range in s): a slope or value wrong anywhere, or a branch point left in, shows
// far above it (a mirrored slope at normal incidence gave 5e-5).
TEST(ThinFilm, TheTabulatedReflectanceIsTheExactOneWithin1e8) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::size_t tables = 0, critical = 0;
    double worst = 0.0;
    for (const auto& entry : std::filesystem::directory_iterator(ff::test::lensPath(""))) {
        if (entry.path().extension() != ".lens") continue;
        const Lens lens = loadLens(entry.path().string());
        for (std::size_t s = 0; s < lens.surfaces.size(); ++s)
            for (double lambda : {450.0, 550.0, 650.0}) {
                const std::vector<FilmLayer> layers = filmLayers(lens.coatingOf(s), lambda);
                const double a = lens.mediumBefore(s).index(lambda), b = lens.surfaces[s].medium.index(lambda);
                if (layers.empty() || a == b) continue;
                const double lo = std::min(a, b), hi = std::max(a, b);
                const std::vector<FilmLayer> reversed(layers.rbegin(), layers.rend());
                for (const auto& [n0, stack, nSub] : {std::tuple(lo, layers, hi), std::tuple(hi, reversed, lo)}) {
                    const FilmReflectanceTable table(n0, stack, nSub, lambda);
                    ++tables;
                    std::vector<double> cosines;
                    for (int k = 0; k < 5000; ++k) cosines.push_back(u(rng));
                    double nMin = nSub;
                    for (const FilmLayer& l : stack) nMin = std::min(nMin, l.n);
                    if (nMin < n0) { // around the critical angle, on both sides of it
                        const double uc = std::sqrt(1.0 - (nMin / n0) * (nMin / n0));
                        for (double e = 1e-12; e < 0.1; e *= 1.7) cosines.push_back(uc + e), cosines.push_back(uc - e);
                        ++critical;
                    }
                    cosines.push_back(1.0);
                    for (double c : cosines) {
                        const double d = std::abs(table(c) - filmReflectance(n0, stack, nSub, c, lambda));
                        worst = std::max(worst, d);
                        ASSERT_LE(d, 1e-8)
                            << entry.path().filename() << " surface " << s << " " << lambda << " nm, cos " << c;
                    }
                }
            }
    }
    EXPECT_GT(tables, 50u);
    EXPECT_GT(critical, 10u);
    std::printf("%zu tables (%zu with a critical angle), worst %.3g\n", tables, critical, worst);
}
