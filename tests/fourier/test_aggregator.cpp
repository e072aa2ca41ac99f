// The Fourier aggregator against the direct sum of the same profiles.

#include "fourier/direct.h"
#include "fourier/render.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <numbers>
#include <random>

namespace ff::fourier {
namespace {

constexpr int kW = 160, kH = 96;

std::vector<Ghost> randomGhosts(int count, Shape shape, double minSize, double maxSize, unsigned seed,
                                double margin = 0.0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Ghost> g(static_cast<std::size_t>(count));
    for (Ghost& k : g) {
        k.shape = shape;
        k.x = margin + u(rng) * (kW - 2.0 * margin);
        k.y = margin + u(rng) * (kH - 2.0 * margin);
        const double sx = minSize * std::pow(maxSize / minSize, u(rng)), aspect = 0.5 + u(rng);
        for (int c = 0; c < 3; ++c) {
            const double chroma = 1.0 + 0.1 * (c - 1); // channels differ in width, as across wavelengths
            k.widthX[c] = sx * chroma;
            k.widthY[c] = sx * aspect * chroma;
            k.flux[c] = 1e-3 * (0.2 + u(rng));
        }
    }
    return g;
}

double relativeL2(const FlareImage& a, const FlareImage& b) {
    double num = 0.0, den = 0.0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t p = 0; p < a.pixels(); ++p) {
            const double d = double(a.channel[c][p]) - double(b.channel[c][p]);
            num += d * d;
            den += double(b.channel[c][p]) * b.channel[c][p];
        }
    return std::sqrt(num / den);
}

FourierSettings allFourier(double error, Evaluation e = Evaluation::Matrix) {
    FourierSettings s;
    s.error = error;
    s.hybrid = false;
    s.evaluation = e;
    return s;
}

TEST(FourierAggregator, MatchesTheDirectSumWithinTheBudget) {
    for (Shape shape : {Shape::Gaussian, Shape::Cos2})
        for (double budget : {1e-2, 1e-3})
            for (Evaluation e : {Evaluation::Matrix, Evaluation::Fft}) {
                SCOPED_TRACE(std::string(toString(shape)) + " budget " + std::to_string(budget) + " " + toString(e));
                const double minSize = shape == Shape::Gaussian ? 3.0 : 8.0;
                const auto ghosts = randomGhosts(40, shape, minSize, 20.0, 7); // all within a period of twice the frame
                const FourierRender f = renderFourier(ghosts, kW, kH, allFourier(budget, e));
                EXPECT_EQ(f.plan.fourier, ghosts.size());
                const FlareImage d = renderDirect(ghosts, kW, kH);
                EXPECT_LE(relativeL2(f.image, d), budget);
            }
}

TEST(FourierAggregator, ImageSumEqualsTheGhostsFlux) {
    // Ghosts well inside the frame: the frame holds all of their flux.
    for (Shape shape : {Shape::Gaussian, Shape::Cos2}) {
        auto ghosts = randomGhosts(30, shape, 1.5, 4.0, 11, 40.0); // 6 sigma inside the frame
        const FourierRender f = renderFourier(ghosts, kW, kH, allFourier(1e-4));
        for (int c = 0; c < 3; ++c) {
            double flux = 0.0;
            for (const Ghost& g : ghosts) flux += g.flux[c];
            EXPECT_NEAR(f.image.sum(c), flux, 1e-4 * flux);
            EXPECT_NEAR(renderDirect(ghosts, kW, kH).sum(c), flux, 1e-6 * flux);
        }
    }
}

TEST(FourierAggregator, SingleCentredGaussianHasTheAnalyticPixelValues) {
    Ghost g;
    g.x = 80.0, g.y = 48.0; // a pixel corner: the four central pixels share the peak
    g.widthX = {6.0, 6.0, 6.0};
    g.widthY = {4.0, 4.0, 4.0};
    g.flux = {1.0, 2.0, 3.0};
    const FourierRender f = renderFourier({g}, kW, kH, allFourier(1e-5));
    // Pixel [80, 81] x [48, 49]: flux x P(0 < X < 1) x P(0 < Y < 1) for the normal distributions.
    auto mass = [](double a, double b, double s) {
        return 0.5 * (std::erf(b / (s * std::numbers::sqrt2)) - std::erf(a / (s * std::numbers::sqrt2)));
    };
    for (int c = 0; c < 3; ++c) {
        const double expected = g.flux[c] * mass(0, 1, 6.0) * mass(0, 1, 4.0);
        EXPECT_NEAR(f.image.channel[c][48 * kW + 80], expected, 1e-4 * expected);
        EXPECT_NEAR(f.image.channel[c][47 * kW + 79], expected, 1e-4 * expected);
        // Far away: nothing.
        EXPECT_NEAR(f.image.channel[c][5 * kW + 5], 0.0, 1e-5 * expected);
    }
}

TEST(FourierAggregator, MovingEveryGhostByOnePeriodChangesNothing) {
    const auto ghosts = randomGhosts(25, Shape::Gaussian, 4.0, 20.0, 3);
    FourierSettings s = allFourier(1e-3);
    s.fixedPeriodX = 256.0;
    s.fixedPeriodY = 160.0;
    s.fixedN = 64;
    s.trimFraction = 0.0;
    auto moved = ghosts;
    for (Ghost& g : moved) g.x += 256.0, g.y -= 160.0;
    // The same plan for both sets (the moved ghosts would be culled by a plan of their own).
    const Plan plan = choosePlan(ghosts, kW, kH, s);
    FlareImage a(kW, kH), b(kW, kH);
    evaluate(accumulate(ghosts, plan, s), Evaluation::Matrix, a);
    evaluate(accumulate(moved, plan, s), Evaluation::Matrix, b);
    EXPECT_LT(relativeL2(b, a), 1e-5);
}

TEST(FourierAggregator, HybridSplitMatchesAllDirectWithinTheBudget) {
    // A mix of small ghosts (cheaper drawn directly) and large ones.
    auto ghosts = randomGhosts(30, Shape::Gaussian, 0.5, 3.0, 5);
    const auto large = randomGhosts(30, Shape::Gaussian, 20.0, 60.0, 6);
    ghosts.insert(ghosts.end(), large.begin(), large.end());
    FourierSettings s;
    s.error = 1e-3;
    s.fixedN = 48; // too few terms for the small ghosts: they must go direct
    const FourierRender f = renderFourier(ghosts, kW, kH, s);
    EXPECT_GT(f.plan.direct, 0u);
    EXPECT_GT(f.plan.fourier, 0u);
    EXPECT_LE(relativeL2(f.image, renderDirect(ghosts, kW, kH)), 1e-3);
}

TEST(FourierAggregator, GhostsOutsideTheFrameAreCulledOrDrawnWithoutWrapping) {
    auto ghosts = randomGhosts(10, Shape::Gaussian, 4.0, 10.0, 9);
    Ghost far = ghosts[0];
    far.x = -500.0; // footprint misses the frame
    ghosts.push_back(far);
    Ghost edge = ghosts[1];
    edge.x = -20.0; // centre outside, light reaching in
    edge.widthX = {15.0, 15.0, 15.0};
    ghosts.push_back(edge);
    FourierSettings s;
    s.error = 1e-3;
    const FourierRender f = renderFourier(ghosts, kW, kH, s);
    EXPECT_EQ(f.plan.culled, 1u);
    EXPECT_LE(relativeL2(f.image, renderDirect(ghosts, kW, kH)), 1e-3);
}

TEST(FourierAggregator, ResultDoesNotDependOnTheThreadCount) {
    const auto ghosts = randomGhosts(200, Shape::Gaussian, 1.0, 30.0, 13);
    FourierSettings s;
    s.error = 1e-3;
    auto render = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        return renderFourier(ghosts, kW, kH, s).image;
    };
    const FlareImage one = render(1), two = render(2);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(one.channel[c], two.channel[c]);
}

TEST(FourierAggregator, DroppingTheDcTermRemovesThePeriodMean) {
    const auto ghosts = randomGhosts(20, Shape::Gaussian, 5.0, 15.0, 17, 30.0);
    FourierSettings s = allFourier(1e-3);
    const FourierRender keep = renderFourier(ghosts, kW, kH, s);
    s.dropDc = true;
    const FourierRender drop = renderFourier(ghosts, kW, kH, s);
    // Without A_00 the series integrates to zero over the period: the frame loses the ghosts' flux
    // minus what the period outside the frame held (nothing), spread as a negative offset.
    for (int c = 0; c < 3; ++c) {
        double flux = 0.0;
        for (const Ghost& g : ghosts) flux += g.flux[c];
        const double area = keep.plan.periodX * keep.plan.periodY;
        EXPECT_NEAR(drop.image.sum(c), keep.image.sum(c) - flux * kW * kH / area, 1e-4 * flux);
    }
}

} // namespace
} // namespace ff::fourier
