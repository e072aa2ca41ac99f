// Gridded accumulation (src/fourier/gridded.h) against the closed-form coefficients written here,
// and the plan's choice between grids and GEMMs.

#include "fourier/aggregate.h"
#include "fourier/evaluate.h"
#include "fourier/gridded.h"
#include "fourier/render.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <numbers>
#include <random>

namespace ff::fourier {
namespace {

constexpr double kPi = std::numbers::pi;

// The profiles' coefficients on period T, independently of coefficients.cpp:
// Gaussian: the transform of exp(-u^2 / 2 s^2) at n / T, over T: (s sqrt(2 pi) / T) exp(-(2 pi n s / T)^2 / 2).
// cos^2(pi u / 2w) on |u| < w: (1/T) Int cos^2(pi u / 2w) cos(2 pi n u / T) du
//   = (w/T) [S(t) + S(t - pi)/2 + S(t + pi)/2], S(u) = sin(u)/u, t = 2 pi n w / T.
double S(double u) {
    return std::abs(u) < 1e-12 ? 1.0 : std::sin(u) / u;
}
double closedForm(Shape shape, int n, double width, double T) {
    if (shape == Shape::Gaussian) {
        const double b = 2.0 * kPi * n * width / T;
        return width * std::sqrt(2.0 * kPi) / T * std::exp(-0.5 * b * b);
    }
    const double t = 2.0 * kPi * n * width / T;
    return width / T * (S(t) + 0.5 * S(t - kPi) + 0.5 * S(t + kPi));
}
double lineIntegral(Shape shape, double width) {
    return shape == Shape::Gaussian ? width * std::sqrt(2.0 * kPi) : width;
}

// Z of one ghost, channel c, over n < nb, m < mb, added into the plan-sized matrix z (2N x 2M):
// A = a cos(n wx x) cos(m wy y), B = a cos sin, C = a sin cos, D = a sin sin, a = alpha p_n q_m.
void addClosedForm(const Ghost& g, int c, int nb, int mb, int N, int M, double Tx, double Ty, std::vector<double>& z) {
    const double alpha = g.flux[c] / (lineIntegral(g.shape, g.widthX[c]) * lineIntegral(g.shape, g.widthY[c]));
    for (int n = 0; n < nb; ++n)
        for (int m = 0; m < mb; ++m) {
            const double a = alpha * closedForm(g.shape, n, g.widthX[c], Tx) * closedForm(g.shape, m, g.widthY[c], Ty);
            const double px = 2.0 * kPi * n * g.x / Tx, py = 2.0 * kPi * m * g.y / Ty;
            z[static_cast<std::size_t>(n) * 2 * M + m] += a * std::cos(px) * std::cos(py);
            z[static_cast<std::size_t>(n) * 2 * M + M + m] += a * std::cos(px) * std::sin(py);
            z[static_cast<std::size_t>(N + n) * 2 * M + m] += a * std::sin(px) * std::cos(py);
            z[static_cast<std::size_t>(N + n) * 2 * M + M + m] += a * std::sin(px) * std::sin(py);
        }
}

std::vector<Ghost> randomGhosts(int count, Shape shape, double minSize, double maxSize, int W, int H, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Ghost> g(static_cast<std::size_t>(count));
    for (Ghost& k : g) {
        k.shape = shape;
        k.x = u(rng) * W;
        k.y = u(rng) * H;
        const double s = minSize * std::pow(maxSize / minSize, u(rng)), aspect = 0.6 + 0.8 * u(rng);
        for (int c = 0; c < 3; ++c) {
            k.widthX[c] = s * (1.0 + 0.08 * c); // channels differ in width, as across wavelengths
            k.widthY[c] = s * aspect * (1.0 + 0.08 * c);
            k.flux[c] = 0.2 + u(rng);
        }
    }
    return g;
}

// Frobenius norm of (a - b) over that of b, all channels.
double relativeDifference(const Coefficients& a, const std::array<std::vector<double>, 3>& b) {
    double num = 0.0, den = 0.0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < b[c].size(); ++i) {
            num += (a.z[c][i] - b[c][i]) * (a.z[c][i] - b[c][i]);
            den += b[c][i] * b[c][i];
        }
    return std::sqrt(num / den);
}

FourierSettings gridSettings(double error) {
    FourierSettings s;
    s.error = error;
    s.hybrid = false;
    s.accumulation = Accumulation::Grid;
    return s;
}

// The grid is sized so that its aliases stay below the trimmed budget (error x trimFraction,
// gridded.h); float32 sampling and transforms add ~1e-6. Every group here is on a grid.
TEST(GriddedAccumulation, MatchesTheClosedFormCoefficients) {
    constexpr int W = 640, H = 360;
    for (Shape shape : {Shape::Gaussian, Shape::Cos2})
        for (double budget : {1e-2, 1e-3}) {
            SCOPED_TRACE(std::string(toString(shape)) + " budget " + std::to_string(budget));
            const auto ghosts = randomGhosts(60, shape, shape == Shape::Gaussian ? 8.0 : 20.0,
                                             shape == Shape::Gaussian ? 60.0 : 150.0, W, H, 7);
            const FourierSettings s = gridSettings(budget);
            const Plan plan = choosePlan(ghosts, W, H, s);
            ASSERT_GT(plan.fourier, 50u);
            std::array<std::vector<double>, 3> expected;
            for (auto& e : expected) e.assign(static_cast<std::size_t>(4) * plan.n * plan.m, 0.0);
            for (const AccumulationGroup& group : plan.groups) {
                ASSERT_EQ(group.method, Accumulation::Grid);
                for (std::size_t k : group.members)
                    for (int c = 0; c < 3; ++c)
                        addClosedForm(ghosts[k], c, group.n, group.m, plan.n, plan.m, plan.periodX, plan.periodY,
                                      expected[c]);
            }
            const double difference = relativeDifference(accumulate(ghosts, plan, s), expected);
            RecordProperty(std::string("relative_difference_") + toString(shape) + "_" + std::to_string(budget),
                           std::to_string(difference));
            EXPECT_LT(difference, budget * s.trimFraction);
        }
}

// A ghost much wider than the period (its stencil covers the grid more than once) and ghosts
// across the period's edges: the periodised Gaussian's coefficients, as the closed form gives them.
TEST(GriddedAccumulation, StencilsWiderThanThePeriodFoldOntoIt) {
    const double T = 240.0;
    std::vector<Ghost> ghosts(3);
    const double xs[3] = {3.0, 236.0, 120.0}, sigmas[3] = {12.0, 15.0, 45.0};
    for (int i = 0; i < 3; ++i) {
        Ghost& g = ghosts[static_cast<std::size_t>(i)];
        g.x = xs[i];
        g.y = T - xs[i];
        for (int c = 0; c < 3; ++c) {
            g.widthX[c] = g.widthY[c] = sigmas[i] * (1.0 + 0.1 * c);
            g.flux[c] = 1.0 + c;
        }
    }
    AccumulationGroup group;
    group.shape = Shape::Gaussian;
    group.n = group.m = 24;
    group.members = {0, 1, 2};
    group.gridX = group.gridY = gridSamples(Shape::Gaussian, group.n, 12.0, T, 2.5e-4);
    for (const Ghost& g : ghosts) group.widestX = group.widestY = std::max(group.widestX, g.widthX[2]);
    // 4.5 sigma either side of the widest (58.5 px) spans 527 px: more than twice the period.
    ASSERT_GT(2.0 * 4.5 * group.widestX, 2.0 * T);
    const auto z = accumulateGridded(ghosts, group, 0, 3, T, T);
    std::array<std::vector<double>, 3> expected;
    for (int c = 0; c < 3; ++c) {
        expected[static_cast<std::size_t>(c)].assign(static_cast<std::size_t>(4) * 24 * 24, 0.0);
        for (const Ghost& g : ghosts) addClosedForm(g, c, 24, 24, 24, 24, T, T, expected[static_cast<std::size_t>(c)]);
    }
    Coefficients got;
    for (int c = 0; c < 3; ++c) got.z[static_cast<std::size_t>(c)] = z[static_cast<std::size_t>(c)];
    EXPECT_LT(relativeDifference(got, expected), 2.5e-4);
}

TEST(GriddedAccumulation, ImageMatchesTheDirectSumWithinTheBudget) {
    constexpr int W = 320, H = 180;
    for (Shape shape : {Shape::Gaussian, Shape::Cos2}) {
        SCOPED_TRACE(toString(shape));
        const auto ghosts = randomGhosts(200, shape, shape == Shape::Gaussian ? 4.0 : 10.0,
                                         shape == Shape::Gaussian ? 40.0 : 100.0, W, H, 11);
        const FourierSettings s = gridSettings(1e-3);
        const FourierRender r = renderFourier(ghosts, W, H, s);
        const FlareImage direct = renderDirect(ghosts, W, H);
        double num = 0.0, den = 0.0;
        for (int c = 0; c < 3; ++c)
            for (std::size_t p = 0; p < direct.pixels(); ++p) {
                const double d = double(r.image.channel[c][p]) - direct.channel[c][p];
                num += d * d;
                den += double(direct.channel[c][p]) * direct.channel[c][p];
            }
        EXPECT_LT(std::sqrt(num / den), 1e-3);
        EXPECT_NE(r.describe().find("accumulated on grids"), std::string::npos) << r.describe();
    }
}

TEST(GriddedAccumulation, ResultDoesNotDependOnTheThreadCount) {
    const auto ghosts = randomGhosts(9000, Shape::Gaussian, 6.0, 50.0, 640, 360, 3);
    const FourierSettings s = gridSettings(1e-3);
    const Plan plan = choosePlan(ghosts, 640, 360, s);
    Coefficients one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = accumulate(ghosts, plan, s);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = accumulate(ghosts, plan, s);
    }
    for (int c = 0; c < 3; ++c) EXPECT_EQ(one.z[static_cast<std::size_t>(c)], two.z[static_cast<std::size_t>(c)]);
}

// Auto weighs a grid's transform against the GEMM's K N M work: few ghosts stay on GEMMs, many
// go to grids; a form that is not the periodised Gaussian never goes to a grid.
TEST(GriddedAccumulation, PlanChoosesGridsForManyGhostsAndGemmsForFew) {
    FourierSettings s;
    s.hybrid = false;
    auto count = [&](const std::vector<Ghost>& g) {
        const Plan plan = choosePlan(g, 1920, 1080, s);
        std::size_t gridded = 0, all = 0;
        for (const AccumulationGroup& group : plan.groups) {
            all += group.members.size();
            if (group.method == Accumulation::Grid) gridded += group.members.size();
        }
        EXPECT_EQ(all, plan.fourier);
        return gridded;
    };
    EXPECT_EQ(count(randomGhosts(10, Shape::Gaussian, 20.0, 80.0, 1920, 1080, 5)), 0u);
    EXPECT_GT(count(randomGhosts(20000, Shape::Gaussian, 20.0, 80.0, 1920, 1080, 5)), 15000u);
    s.accumulation = Accumulation::Grid;
    s.gaussianForm = GaussianForm::Exact;
    EXPECT_EQ(count(randomGhosts(200, Shape::Gaussian, 20.0, 80.0, 1920, 1080, 5)), 0u);
    s.accumulation = Accumulation::Gemm;
    s.gaussianForm = GaussianForm::Periodised;
    EXPECT_EQ(count(randomGhosts(20000, Shape::Gaussian, 20.0, 80.0, 1920, 1080, 5)), 0u);
}

TEST(FourierEvaluation, AddingWritesTheSumOfTheImageAndTheSeries) {
    const auto ghosts = randomGhosts(20, Shape::Gaussian, 5.0, 30.0, 200, 120, 2);
    FourierSettings s;
    s.hybrid = false;
    s.fixedPeriodX = 400;
    s.fixedPeriodY = 240;
    const Plan plan = choosePlan(ghosts, 200, 120, s);
    const Coefficients z = accumulate(ghosts, plan, s);
    for (Evaluation e : {Evaluation::Matrix, Evaluation::Fft}) {
        FlareImage series(200, 120), sum(200, 120);
        for (int c = 0; c < 3; ++c)
            for (std::size_t p = 0; p < sum.pixels(); ++p) sum.channel[c][p] = 0.25f * float(c + 1);
        evaluate(z, e, series, Write::Replace);
        evaluate(z, e, sum, Write::Add);
        for (int c = 0; c < 3; ++c)
            for (std::size_t p = 0; p < sum.pixels(); p += 97)
                EXPECT_NEAR(sum.channel[c][p], series.channel[c][p] + 0.25f * float(c + 1), 1e-6f) << toString(e);
    }
}

} // namespace
} // namespace ff::fourier
