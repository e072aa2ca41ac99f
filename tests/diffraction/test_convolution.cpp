// The FFT convolution of the lights' image with the PSF against the direct sum (zero outside the
// frame), and the diffraction layer's energy rule.

#include "diffraction/convolution.h"
#include "diffraction/psf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace ff::diffraction {
namespace {

Psf randomKernel(int radius, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Psf psf;
    psf.radius = radius;
    const int w = psf.width();
    for (auto& ch : psf.channel) {
        ch.resize(static_cast<std::size_t>(w) * w);
        double sum = 0.0;
        for (auto& v : ch) sum += (v = static_cast<float>(u(rng) * u(rng)));
        for (auto& v : ch) v = static_cast<float>(v / sum);
    }
    return psf;
}

// Both routes against the sum written out here: a few lights at random (some at the frame's edges:
// the kernel added at each) and a frame lit everywhere (by FFT).
void expectTheDirectSum(const std::vector<float>& image, int W, int H, const Psf& psf) {
    double off = 0.0;
    const auto fft = convolve(image, W, H, psf, &off);
    double num = 0.0, den = 0.0, in = 0.0, kept = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                double direct = 0.0;
                for (int dy = -psf.radius; dy <= psf.radius; ++dy)
                    for (int dx = -psf.radius; dx <= psf.radius; ++dx) {
                        const int sx = x - dx, sy = y - dy;
                        if (sx < 0 || sy < 0 || sx >= W || sy >= H) continue;
                        direct += image[(static_cast<std::size_t>(sy) * W + sx) * 3 + c] * double(psf.at(c, dx, dy));
                    }
                const double d = fft[(static_cast<std::size_t>(y) * W + x) * 3 + c] - direct;
                num += d * d;
                den += direct * direct;
                in += image[(static_cast<std::size_t>(y) * W + x) * 3 + c];
                kept += direct;
            }
    EXPECT_LT(std::sqrt(num / den), 1e-5);
    EXPECT_NEAR(off, in - kept, 1e-4 * in);
    EXPECT_GT(off, 0.0);
}

TEST(Convolution, MatchesTheDirectSum) {
    const int W = 37, H = 23;
    const Psf psf = randomKernel(6, 3);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<float> image(static_cast<std::size_t>(W) * H * 3, 0.0f);
    for (int k = 0; k < 12; ++k) // lights, some at the frame's edges
        for (int c = 0; c < 3; ++c)
            image[(static_cast<std::size_t>(rng() % H) * W + rng() % W) * 3 + c] = static_cast<float>(100.0 * u(rng));
    ASSERT_TRUE(convolvesDirectly(image, W, H, psf));
    expectTheDirectSum(image, W, H, psf);
    for (float& v : image) v += static_cast<float>(u(rng));
    ASSERT_FALSE(convolvesDirectly(image, W, H, psf));
    expectTheDirectSum(image, W, H, psf);
}

// A convolver kept from frame to frame (its kernel's spectra kept while the frame's size, the PSF
// and the periods stay) gives what a fresh one gives, to the bit, as the lights' reach and the PSF
// change; the lights fill enough of the frame for the transforms.
TEST(Convolution, AKeptConvolverGivesWhatAFreshOneGives) {
    const int W = 90, H = 50;
    PsfSettings s;
    s.pitchMm = 36.0 / W;
    s.wavelengthsNm = {450.0, 550.0, 650.0};
    s.transform = 256;
    const Psf six = pixelPsf({6, 0.0, 8.0}, s), five = pixelPsf({5, 9.0, 11.0}, s);
    ASSERT_FALSE(six.far.empty());
    const auto frame = [&](int x0, int y0, int x1, int y1, unsigned seed) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        std::vector<float> image(static_cast<std::size_t>(W) * H * 3, 0.0f);
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x)
                for (int c = 0; c < 3; ++c)
                    image[(static_cast<std::size_t>(y) * W + x) * 3 + c] = static_cast<float>(100.0 * u(rng));
        return image;
    };
    struct Case {
        std::vector<float> image;
        const Psf* psf;
    };
    // The second and third frames need the same periods (their lights reach 59 and 58 px across, 34
    // down), the fourth only changes the PSF.
    const Case cases[] = {{frame(0, 0, W, H, 1), &six},     {frame(30, 15, 60, 35, 2), &six},
                          {frame(31, 16, 59, 35, 3), &six}, {frame(31, 16, 59, 35, 3), &five},
                          {frame(0, 0, W, H, 1), &six},     {frame(30, 15, 60, 35, 4), &five}};
    FftwConvolver kept;
    for (const Case& k : cases) {
        ASSERT_FALSE(convolvesDirectly(k.image, W, H, *k.psf));
        double offKept = 0.0, offFresh = 0.0;
        const auto a = kept.convolve(k.image, W, H, *k.psf, &offKept);
        const auto b = convolve(k.image, W, H, *k.psf, &offFresh);
        EXPECT_EQ(a, b);
        EXPECT_EQ(offKept, offFresh);
    }
}

// A light outside the frame reaches into it as it does on a frame large enough to hold it: the
// convolution commutes with translation, so this frame is a window of that one (there by convolve's
// routes, tested against the direct sum above). What the window misses of the light's flux (1 per
// channel with a far field, the square's sum without) is what the large frame keeps outside the
// window plus what it loses itself.
TEST(Convolution, ALightOutsideTheFrameReachesInAsOnALargerFrame) {
    const int W = 90, H = 50, pad = 40, LW = W + 2 * pad, LH = H + 2 * pad;
    PsfSettings s;
    s.pitchMm = 36.0 / W;
    s.wavelengthsNm = {450.0, 550.0, 650.0};
    s.transform = 256;
    const Psf six = pixelPsf({6, 0.0, 8.0}, s), square = randomKernel(6, 3);
    ASSERT_FALSE(six.far.empty());
    ASSERT_TRUE(square.far.empty());
    const std::array<double, 3> flux{2.0, 1.0, 0.5};
    struct Case {
        const Psf* psf;
        int x, y;
        bool reaches; ///< whether any of the kernel lands in the frame
    };
    const Case cases[] = {{&six, -25, 17, true},       {&six, W + 10, -8, true},  {&six, -3, H + 30, true},
                          {&square, -3, 17, true},     {&square, W + 5, H, true}, {&square, -25, 17, false},
                          {&square, W + 10, -8, false}};
    for (const Case& k : cases) {
        std::vector<float> window(static_cast<std::size_t>(W) * H * 3, 0.0f);
        double off = 0.0;
        addOutsideLight(*k.psf, k.x, k.y, flux, W, H, window, &off);
        std::vector<float> large(static_cast<std::size_t>(LW) * LH * 3, 0.0f);
        const std::size_t at = (static_cast<std::size_t>(k.y + pad) * LW + (k.x + pad)) * 3;
        for (std::size_t c = 0; c < 3; ++c) large[at + c] = static_cast<float>(flux[c]);
        double largeOff = 0.0;
        const std::vector<float> all = convolve(large, LW, LH, *k.psf, &largeOff);
        double beyond = 0.0, peak = 0.0;
        for (int y = 0; y < LH; ++y)
            for (int x = 0; x < LW; ++x)
                for (int c = 0; c < 3; ++c) {
                    const double v = all[(static_cast<std::size_t>(y) * LW + x) * 3 + c];
                    if (x < pad || y < pad || x >= pad + W || y >= pad + H) {
                        beyond += v;
                        continue;
                    }
                    const float got = window[(static_cast<std::size_t>(y - pad) * W + (x - pad)) * 3 + c];
                    EXPECT_NEAR(got, v, 1e-6 * std::abs(v) + 1e-12)
                        << k.x << "," << k.y << " at " << x - pad << "," << y - pad << " channel " << c;
                    peak = std::max(peak, v);
                }
        EXPECT_EQ(peak > 0.0, k.reaches) << k.x << "," << k.y;
        EXPECT_NEAR(off, beyond + largeOff, 1e-5 * 3.5) << k.x << "," << k.y;
    }
}

// One light in the middle: the layer is the kernel around it minus the light, summing to zero; it is
// linear in the light and in the gain.
TEST(Convolution, TheLayerRedistributesTheLightsFlux) {
    const int W = 41, H = 41;
    const Psf psf = randomKernel(8, 9);
    std::vector<float> lights(static_cast<std::size_t>(W) * H * 3, 0.0f);
    const std::size_t centre = (static_cast<std::size_t>(20) * W + 20) * 3;
    lights[centre] = 500.0f, lights[centre + 1] = 200.0f, lights[centre + 2] = 50.0f;
    double off = 0.0;
    const auto layer = diffractionLayer(lights, W, H, psf, 1.0, &off);
    EXPECT_NEAR(off, 0.0, 1e-3);
    std::array<double, 3> sum{};
    for (std::size_t i = 0; i < layer.size(); ++i) sum[i % 3] += layer[i];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[static_cast<std::size_t>(c)], 0.0, 1e-4 * 500.0) << c;
    for (int c = 0; c < 3; ++c)
        for (int dy = -8; dy <= 8; ++dy)
            for (int dx = -8; dx <= 8; ++dx) {
                const float light = lights[centre + static_cast<std::size_t>(c)];
                const float expected = light * psf.at(c, dx, dy) - (dx == 0 && dy == 0 ? light : 0.0f);
                EXPECT_NEAR(layer[(static_cast<std::size_t>(20 + dy) * W + (20 + dx)) * 3 + c], expected, 1e-4 * light);
            }
    std::vector<float> doubled = lights;
    for (float& v : doubled) v *= 2.0f;
    const auto twice = diffractionLayer(doubled, W, H, psf, 1.0);
    const auto half = diffractionLayer(lights, W, H, psf, 0.5);
    for (std::size_t i = 0; i < layer.size(); ++i) {
        EXPECT_NEAR(twice[i], 2.0f * layer[i], 1e-4f * 500.0f);
        EXPECT_NEAR(half[i], 0.5f * layer[i], 1e-4f * 500.0f);
    }
}

// Tiles: each tile's lights get the PSF chosen at their flux-weighted centre (derived here
// from the lights placed); with one PSF for every tile the layer is the unzoned one (at gain 1 the
// layer's floor -lights never binds, so splitting the lights changes nothing but rounding).
TEST(Convolution, ZonesConvolveEachTilesLightsWithItsOwnPsf) {
    const int W = 60, H = 30;
    const Psf one = randomKernel(6, 3), other = randomKernel(6, 4);
    std::vector<float> lights(static_cast<std::size_t>(W) * H * 3, 0.0f);
    auto put = [&](int x, int y, float r, float g, float b) {
        const std::size_t p = (static_cast<std::size_t>(y) * W + x) * 3;
        lights[p] = r, lights[p + 1] = g, lights[p + 2] = b;
    };
    put(3, 4, 100.0f, 100.0f, 100.0f); // tile (0, 0) of 3 x 2 (20 x 15 pixels each)
    put(9, 10, 300.0f, 0.0f, 0.0f);    // tile (0, 0)
    put(45, 20, 10.0f, 20.0f, 30.0f);  // tile (2, 1)
    std::vector<std::pair<double, double>> asked;
    const auto zoned = sumOverTiles(lights, W, H, 3, 2, [&](const std::vector<float>& tile, double x, double y) {
        asked.push_back({x, y});
        return diffractionLayer(tile, W, H, one, 1.0);
    });
    ASSERT_EQ(asked.size(), 2u);
    // (3.5, 4.5) with 300, (9.5, 10.5) with 300; (45.5, 20.5) alone.
    EXPECT_NEAR(asked[0].first, 6.5, 1e-9);
    EXPECT_NEAR(asked[0].second, 7.5, 1e-9);
    EXPECT_NEAR(asked[1].first, 45.5, 1e-9);
    EXPECT_NEAR(asked[1].second, 20.5, 1e-9);
    const auto whole = diffractionLayer(lights, W, H, one, 1.0);
    for (std::size_t i = 0; i < whole.size(); ++i) EXPECT_NEAR(zoned[i], whole[i], 1e-5f * 300.0f) << i;

    // A different PSF per tile: each tile's part is its lights through its own kernel.
    const auto mixed = sumOverTiles(lights, W, H, 3, 2, [&](const std::vector<float>& tile, double x, double) {
        return diffractionLayer(tile, W, H, x < 20 ? one : other, 1.0);
    });
    std::vector<float> left = lights, right = lights;
    for (std::size_t p = 0; p < lights.size() / 3; ++p)
        (p % W < 20 ? right : left)[3 * p] = 0.0f, (p % W < 20 ? right : left)[3 * p + 1] = 0.0f,
                                        (p % W < 20 ? right : left)[3 * p + 2] = 0.0f;
    const auto a = diffractionLayer(left, W, H, one, 1.0), b = diffractionLayer(right, W, H, other, 1.0);
    for (std::size_t i = 0; i < mixed.size(); ++i) EXPECT_NEAR(mixed[i], a[i] + b[i], 1e-5f * 300.0f) << i;
}

} // namespace
} // namespace ff::diffraction
