// The PSF's far field against edge diffraction's law, derived here: a straight edge of length L in a
// pupil of area A (both in units of the pupil's diameter D) sends into the line along its normal the
// share L beta / (4 pi^2 A r^2) of the flux per pixel of length at r pixels (beta = lambda N / pitch),
// from |P^(nu)| -> L / (2 pi |nu|) on the line and the sinc^2 across it integrating to beta / L;
// the hexagon's two parallel edges per line add (their fringes average over a pixel and the
// spectrum). And the joined kernel against the same transform four times larger (whose near field
// reaches four times as far), its flux, and no false cross.

#include "diffraction/convolution.h"
#include "diffraction/far_field.h"
#include "diffraction/psf.h"
#include "trace/traced_flare.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ff::diffraction {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kPitch = 36.0 / 1920.0; // a full-frame 1080p sensor, mm

// The default wavelengths and their channel weights: linear sRGB, negatives clipped, each channel
// summing to 1 (psf.h).
void defaultWeights(std::vector<double>& nm, std::vector<std::array<double, 3>>& w) {
    trace::colourWeights(8, nm, w);
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (auto& x : w) sum += (x[c] = std::max(0.0, x[c]));
        for (auto& x : w) x[c] /= sum;
    }
}

// A hexagon of equal area pi / 4 (diameter 1) has side sqrt(pi / (6 sqrt 3)).
double hexagonLaw(double r, double beta) {
    const double L = std::sqrt(kPi / (6.0 * std::sqrt(3.0))), A = kPi / 4.0;
    return 2.0 * L * beta / (4.0 * kPi * kPi * A * r * r);
}

TEST(FarField, SpikesFollowTheEdgeDiffractionLaw) {
    // Six blades, one pair of edges with normals along +-x: a spike along the frame's x axis.
    const Aperture a{6, -kPi / 6.0, 8.0};
    PsfSettings s;
    s.pitchMm = kPitch;
    const Psf psf = pixelPsf(a, s);
    std::vector<double> nm;
    std::vector<std::array<double, 3>> w;
    defaultWeights(nm, w);
    for (int c = 0; c < 3; ++c) {
        const std::vector<float> k = frameKernel(psf, c, 320, 8);
        for (int r = 30; r <= 300; r += 5) {
            double across = 0.0, law = 0.0;
            for (int dy = -8; dy <= 8; ++dy) across += k[static_cast<std::size_t>(dy + 8) * 641 + (r + 320)];
            for (std::size_t i = 0; i < nm.size(); ++i) law += w[i][c] * hexagonLaw(r, nm[i] * 1e-6 * 8.0 / kPitch);
            EXPECT_NEAR(across / law, 1.0, 0.1) << "r " << r << " channel " << c << " (radius " << psf.radius << ")";
        }
    }
}

// The radial profile (each 1-pixel ring's share) of the joined kernel against the same PSF from a
// transform four times larger, whose near field (the FFT's own) reaches four times as far: no seam
// where the near field hands over, and the far field continuing the FFT's own values.
TEST(FarField, TheJoinLeavesNoSeam) {
    const Aperture a{6, 0.3, 8.0};
    PsfSettings s;
    s.pitchMm = kPitch;
    s.transform = 1024;
    const Psf joined = pixelPsf(a, s);
    s.transform = 4096;
    const Psf reference = pixelPsf(a, s);
    ASSERT_GE(reference.radius, 4 * joined.radius - 8);
    const int reach = reference.radius / 4; // the reference's own near field
    for (int c = 0; c < 3; ++c) {
        const std::vector<float> k = frameKernel(joined, c, reach, reach);
        std::vector<double> ring(static_cast<std::size_t>(reach) + 1, 0.0), want(ring.size(), 0.0);
        for (int dy = -reach; dy <= reach; ++dy)
            for (int dx = -reach; dx <= reach; ++dx) {
                const auto r = static_cast<std::size_t>(std::hypot(dx, dy));
                if (r > static_cast<std::size_t>(reach)) continue;
                ring[r] += k[static_cast<std::size_t>(dy + reach) * (2 * reach + 1) + (dx + reach)];
                want[r] += reference.at(c, dx, dy);
            }
        for (int r = 3; r < reach; ++r)
            EXPECT_NEAR(ring[static_cast<std::size_t>(r)] / want[static_cast<std::size_t>(r)], 1.0, 0.02)
                << "ring " << r << " channel " << c << " (joined from " << joined.radius / 5 << " px)";
    }
}

// Every channel sums to 1 over the plane: what the kernel holds within X of the light falls short of
// 1 by the 1 / r^2 spikes' share beyond X, so by a quarter as much at 4 X.
TEST(FarField, TheKernelCarriesTheWholeFlux) {
    const Aperture a{7, 0.1, 5.6};
    PsfSettings s;
    s.pitchMm = kPitch;
    const Psf psf = pixelPsf(a, s);
    EXPECT_LT(psf.outside, 2e-3);
    for (int c = 0; c < 3; ++c) {
        double near = 0.0, far = 0.0;
        for (float v : frameKernel(psf, c, 400, 400)) near += v;
        for (float v : frameKernel(psf, c, 1600, 1600)) far += v;
        EXPECT_GT(1.0 - near, 0.0) << c;
        EXPECT_NEAR((1.0 - far) / (1.0 - near), 0.25, 0.05) << c;
        EXPECT_LT(1.0 - far, 1e-3) << c;
    }
}

// Five blades: ten spikes, none along the frame's axes (the nearest 9 degrees away). Along the axes
// the kernel holds only the faint halo between spikes, however far: no cross folded in from the
// transform's period or drawn by the kernel's square.
TEST(FarField, NoFalseCross) {
    const Aperture a{5, 9.0 * kPi / 180.0, 8.0};
    PsfSettings s;
    s.pitchMm = kPitch;
    const Psf psf = pixelPsf(a, s);
    const int reach = 400;
    const std::vector<float> k = frameKernel(psf, 1, reach, reach);
    auto at = [&](double x, double y) {
        return k[static_cast<std::size_t>(std::lround(y) + reach) * (2 * reach + 1) + (std::lround(x) + reach)];
    };
    for (int r = psf.radius / 5; r <= reach; r += 7) {
        // The spike at 9 degrees from +x (pixel rows down: at -9 degrees on the frame).
        const double t = -9.0 * kPi / 180.0;
        const double spike = at(r * std::cos(t), r * std::sin(t));
        for (auto [x, y] : {std::pair{r, 0}, {-r, 0}, {0, r}, {0, -r}})
            EXPECT_LT(at(x, y), 0.02 * spike) << "r " << r << " at " << x << "," << y;
    }
}

} // namespace
} // namespace ff::diffraction
