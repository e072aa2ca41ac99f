// Dirt on the front element: procedural dirt is the same for the same seed, and the diffraction of a
// straight scratch is a streak across it (a thin opaque line's transform is a line through the
// origin perpendicular to it: sinc(pi w nu_perp) along nu_perp, narrow along the scratch).

#include "diffraction/psf.h"
#include "diffraction/pupil_mask.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace ff::diffraction {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(PupilMask, TheSameSeedGivesTheSameDirt) {
    const PupilMask a = proceduralDirt(7, 1.0), b = proceduralDirt(7, 1.0), c = proceduralDirt(8, 1.0);
    EXPECT_EQ(a.transmittance, b.transmittance);
    EXPECT_EQ(a.key, b.key);
    EXPECT_NE(a.transmittance, c.transmittance);
    EXPECT_NE(a.key, c.key);
    // More dirt blocks more light; every value a transmittance.
    auto blocked = [](const PupilMask& m) {
        double sum = 0.0;
        for (float t : m.transmittance) {
            EXPECT_TRUE(t >= 0.0f && t <= 1.0f);
            sum += 1.0 - t;
        }
        return sum;
    };
    EXPECT_GT(blocked(proceduralDirt(7, 3.0)), 2.0 * blocked(a));
    EXPECT_GT(blocked(a), 0.0);
    for (double bad : {0.0, -1.0, 101.0, double(NAN)}) EXPECT_THROW(proceduralDirt(7, bad), Error) << bad;
    // The PSF through it: the same bytes twice.
    PsfSettings s;
    s.pitchMm = 0.02;
    s.wavelengthsNm = {550.0};
    s.transform = 512;
    s.mask = std::make_shared<PupilMask>(a);
    const Psf p = pixelPsf({6, 0.0, 8.0}, s), q = pixelPsf({6, 0.0, 8.0}, s);
    for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(p.channel[ch], q.channel[ch]);
}

// One straight opaque scratch at 20 degrees across a round iris (an image: the mask's own path): what
// it adds to the PSF lies along the perpendicular, at 110 degrees (the frame's +y up), within 1 degree.
TEST(PupilMask, AScratchDiffractsIntoAStreakAcrossIt) {
    const int n = 512;
    const double angle = 20.0 * kPi / 180.0, half = 0.006; // of the circumradius
    std::vector<float> pixels(static_cast<std::size_t>(n) * n, 1.0f);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double u = 2.0 * (i + 0.5) / n - 1.0, v = 1.0 - 2.0 * (j + 0.5) / n;
            if (std::abs(-u * std::sin(angle) + v * std::cos(angle)) < half && std::hypot(u, v) < 0.8)
                pixels[static_cast<std::size_t>(j) * n + i] = 0.0f;
        }
    PsfSettings s;
    s.pitchMm = 0.01;
    s.wavelengthsNm = {550.0};
    const Aperture round{0, 0.0, 4.0};
    const Psf clean = pixelPsf(round, s);
    s.mask = std::make_shared<PupilMask>(maskFromImage(pixels, n, n, 1, 0, -1, -1, "scratch"));
    const Psf dirty = pixelPsf(round, s);
    ASSERT_EQ(clean.radius, dirty.radius);
    const int R = clean.radius;
    double c2 = 0.0, s2 = 0.0;
    for (int dy = -R; dy <= R; ++dy)
        for (int dx = -R; dx <= R; ++dx) {
            const double r = std::hypot(dx, dy);
            if (r < 0.15 * R || r > 0.55 * R) continue;
            const double w = std::abs(dirty.at(1, dx, dy) - clean.at(1, dx, dy));
            const double a = std::atan2(-double(dy), double(dx)); // +y up
            c2 += w * std::cos(2.0 * a);
            s2 += w * std::sin(2.0 * a);
        }
    double streak = 0.5 * std::atan2(s2, c2) * 180.0 / kPi; // an axis: modulo 180 degrees
    if (streak < 0.0) streak += 180.0;
    EXPECT_NEAR(streak, 110.0, 1.0);
    // And strongly so: the weights concentrated along it.
    EXPECT_GT(std::hypot(c2, s2), 0.0);
}

TEST(PupilMask, ImagesAreFittedAndCheckedAndMasksCombine) {
    // 4 x 2: the centred square is columns 1-2; luminance of RGB.
    std::vector<float> rgb(4 * 2 * 3, 1.0f);
    rgb[(0 * 4 + 1) * 3 + 1] = 0.0f; // green 0 at (1, 0): luminance 1 - 0.7152
    const PupilMask m = maskFromImage(rgb, 4, 2, 3, 0, 1, 2, "rgb");
    ASSERT_EQ(m.size, 2);
    EXPECT_NEAR(m.transmittance[0], 1.0 - 0.7152, 1e-6);
    EXPECT_EQ(m.transmittance[1], 1.0f);
    EXPECT_DOUBLE_EQ(m.at(5.0, 5.0), 1.0); // beyond the raster: clear
    EXPECT_NEAR(m.at(-0.5, 0.5), 1.0 - 0.7152, 1e-6);
    rgb[5] = NAN;
    EXPECT_THROW(maskFromImage(rgb, 4, 2, 3, 0, 1, 2, "nan"), Error);
    const PupilMask both = combine(m, m);
    EXPECT_NEAR(both.transmittance[0], (1.0 - 0.7152) * (1.0 - 0.7152), 1e-6);
    EXPECT_TRUE(combine(PupilMask{}, PupilMask{}).empty());
}

} // namespace
} // namespace ff::diffraction
