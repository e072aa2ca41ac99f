// Fourier aggregation benchmarks at 1920 x 1080 RGB (docs/performance.md):
//  - evaluation of given coefficients, matrix form vs FFT form, at N = 64, 128, 256;
//  - the GEMM floor: OpenBLAS sgemm of exactly the evaluation's two products per channel, the
//    baseline every evaluation time is read against;
//  - accumulation + evaluation against the number of ghosts K, and the direct alternatives: per-pixel
//    full-frame sum, separable full-frame sum (outer products as one GEMM of inner size K) and
//    drawing clipped to each ghost's footprint;
//  - the shaped hybrid's grid to its coefficients: cell by cell (fourier::accumulateSampled, which
//    gpu::GlSampled ran on the GPU) against one FFT of the grid (accumulateSampledGrid).

#include "fourier/aggregate.h"
#include "fourier/direct.h"
#include "fourier/render.h"
#include "fourier/sampled.h"

#include <benchmark/benchmark.h>

#include <cblas.h>
#include <cmath>
#include <numbers>
#include <random>

namespace {

using namespace ff::fourier;

constexpr int kW = 1920, kH = 1080;
// A period every benchmark ghost fits in without wrapping (centres in the frame, sigma <= 120 px x 1.1).
constexpr double kTx = 3200.0, kTy = 1800.0;

// K Gaussian ghosts with sigma 30-120 px (all within N = 64 terms at the 1e-3 budget on this period).
std::vector<Ghost> ghosts(int K, double minSigma = 30.0, double maxSigma = 120.0) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Ghost> g(static_cast<std::size_t>(K));
    for (Ghost& k : g) {
        k.x = u(rng) * kW;
        k.y = u(rng) * kH;
        const double s = minSigma * std::pow(maxSigma / minSigma, u(rng));
        for (int c = 0; c < 3; ++c) {
            k.widthX[c] = s * (1.0 + 0.05 * c);
            k.widthY[c] = s * (0.8 + 0.05 * c);
            k.flux[c] = u(rng);
        }
    }
    return g;
}

FourierSettings fixed(int n) {
    FourierSettings s;
    s.fixedN = n;
    s.fixedPeriodX = kTx;
    s.fixedPeriodY = kTy;
    s.hybrid = false;
    return s;
}

// The coefficients of 100 ghosts at N terms, for the evaluation benchmarks.
Coefficients coefficientsAt(int n) {
    const auto g = ghosts(100);
    const FourierSettings s = fixed(n);
    return accumulate(g, choosePlan(g, kW, kH, s), s);
}

void BM_Evaluate(benchmark::State& state, Evaluation e) {
    const Coefficients z = coefficientsAt(static_cast<int>(state.range(0)));
    FlareImage image(kW, kH);
    for (auto _ : state) {
        evaluate(z, e, image);
        benchmark::DoNotOptimize(image.channel[0].data());
    }
    state.counters["M"] = z.m;
}
BENCHMARK_CAPTURE(BM_Evaluate, matrix, Evaluation::Matrix)
    ->Arg(64)
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Evaluate, fft, Evaluation::Fft)
    ->Arg(64)
    ->Arg(128)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The same two sgemm calls per channel as the matrix evaluation, on ready float matrices.
void BM_GemmFloor(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    const int m = static_cast<int>(std::ceil(n * kTy / kTx));
    std::vector<float> Z(static_cast<std::size_t>(4) * n * m, 0.5f), Y(static_cast<std::size_t>(2) * m * kH, 0.25f),
        X(static_cast<std::size_t>(2) * n * kW, 0.25f), T(static_cast<std::size_t>(2) * n * kH),
        I(static_cast<std::size_t>(kW) * kH);
    for (auto _ : state)
        for (int c = 0; c < 3; ++c) {
            cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, 2 * n, kH, 2 * m, 1.0f, Z.data(), 2 * m, Y.data(),
                        kH, 0.0f, T.data(), kH);
            cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, kH, kW, 2 * n, 1.0f, T.data(), kH, X.data(), kW, 0.0f,
                        I.data(), kW);
            benchmark::DoNotOptimize(I.data());
        }
    state.counters["GFLOP/s"] = benchmark::Counter(3.0 * (8.0 * n * m * kH + 4.0 * n * double(kW) * kH),
                                                   benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_GemmFloor)->Arg(64)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();

// Accumulation + evaluation at N = 64 against K.
void BM_FourierTotal(benchmark::State& state) {
    const auto g = ghosts(static_cast<int>(state.range(0)));
    const FourierSettings s = fixed(64);
    for (auto _ : state) {
        const FourierRender r = renderFourier(g, kW, kH, s);
        benchmark::DoNotOptimize(r.image.channel[0].data());
    }
}
BENCHMARK(BM_FourierTotal)->RangeMultiplier(10)->Range(10, 100000)->Unit(benchmark::kMillisecond)->UseRealTime();

// Accumulation alone against K, by method (docs/fourier.md, "Gridded accumulation"): every group as
// a GEMM, every group on a grid, or the plan's choice per group.
void BM_Accumulate(benchmark::State& state, Accumulation method) {
    const auto g = ghosts(static_cast<int>(state.range(0)));
    FourierSettings s = fixed(64);
    s.accumulation = method;
    const Plan plan = choosePlan(g, kW, kH, s);
    for (auto _ : state) {
        const Coefficients z = accumulate(g, plan, s);
        benchmark::DoNotOptimize(z.z[0].data());
    }
    std::size_t gridded = 0;
    for (const AccumulationGroup& group : plan.groups)
        gridded += group.method == Accumulation::Grid ? group.members.size() : 0;
    state.counters["gridded"] = double(gridded);
}
BENCHMARK_CAPTURE(BM_Accumulate, gemm, Accumulation::Gemm)
    ->RangeMultiplier(10)
    ->Range(100, 100000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Accumulate, grid, Accumulation::Grid)
    ->RangeMultiplier(10)
    ->Range(100, 100000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Accumulate, auto, Accumulation::Auto) -> RangeMultiplier(10) -> Range(100, 100000)
    -> Unit(benchmark::kMillisecond) -> UseRealTime();

// Every ghost evaluated at every pixel (pixel centres, no footprint): K W H exponentials per channel.
// The shaped hybrid's grid (scene::drawShaped: 4-pixel cells over the frame and 8 cells of margin,
// every term below its Nyquist frequency) to its coefficients. Arg: the frame's width (height 9/16 of
// it); capture: cell-by-cell sums or one r2c FFT per channel.
void BM_SampledGrid(benchmark::State& state, bool fft) {
    const int w = static_cast<int>(state.range(0)), h = w * 9 / 16;
    SampledGhost g;
    g.step = 4.0;
    g.width = fftFriendly((w + 3) / 4 + 16);
    g.height = fftFriendly((h + 3) / 4 + 16);
    g.x0 = -(std::floor((g.width * g.step - w) / (2.0 * g.step)) + 0.5) * g.step;
    g.y0 = -(std::floor((g.height * g.step - h) / (2.0 * g.step)) + 0.5) * g.step;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    g.values.resize(static_cast<std::size_t>(g.width) * g.height * 3);
    for (float& v : g.values) v = u(rng);
    for (auto _ : state) {
        Coefficients z;
        z.n = g.width / 2;
        z.m = g.height / 2;
        z.periodX = g.width * g.step;
        z.periodY = g.height * g.step;
        for (auto& ch : z.z) ch.assign(static_cast<std::size_t>(4) * z.n * z.m, 0.0);
        if (fft)
            accumulateSampledGrid(g, z);
        else
            accumulateSampled({g}, z);
        benchmark::DoNotOptimize(z.z[0].data());
    }
    state.counters["cells"] = double(g.width) * g.height;
}
BENCHMARK_CAPTURE(BM_SampledGrid, sums, false)
    ->Arg(640)
    ->Arg(1280)
    ->Arg(1920)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_SampledGrid, fft, true)
    ->Arg(640)
    ->Arg(1280)
    ->Arg(1920)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_DirectFullFrame(benchmark::State& state) {
    const auto g = ghosts(static_cast<int>(state.range(0)));
    FlareImage image(kW, kH);
    for (auto _ : state) {
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < kH; ++y) {
                float* row = &image.channel[c][static_cast<std::size_t>(y) * kW];
                for (int x = 0; x < kW; ++x) {
                    double v = 0.0;
                    for (const Ghost& k : g) {
                        const double dx = (x + 0.5 - k.x) / k.widthX[c], dy = (y + 0.5 - k.y) / k.widthY[c];
                        v += k.peak(c) * std::exp(-0.5 * (dx * dx + dy * dy));
                    }
                    row[x] = static_cast<float>(v);
                }
            }
        benchmark::DoNotOptimize(image.channel[0].data());
    }
}
BENCHMARK(BM_DirectFullFrame)->Arg(10)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// Separable full frame: per channel, image (H x W) = Gy^T (H x K) diag(alpha) Gx (K x W), one GEMM.
void BM_DirectSeparable(benchmark::State& state) {
    const int K = static_cast<int>(state.range(0));
    const auto g = ghosts(K);
    std::vector<float> gx(static_cast<std::size_t>(K) * kW), gy(static_cast<std::size_t>(K) * kH),
        image(static_cast<std::size_t>(kW) * kH);
    for (auto _ : state)
        for (int c = 0; c < 3; ++c) {
            for (int k = 0; k < K; ++k) {
                const Ghost& q = g[static_cast<std::size_t>(k)];
                for (int x = 0; x < kW; ++x)
                    gx[static_cast<std::size_t>(k) * kW + x] =
                        static_cast<float>(q.peak(c) * profileIntegral(q.shape, q.widthX[c], x - q.x, x + 1 - q.x));
                for (int y = 0; y < kH; ++y)
                    gy[static_cast<std::size_t>(k) * kH + y] =
                        static_cast<float>(profileIntegral(q.shape, q.widthY[c], y - q.y, y + 1 - q.y));
            }
            cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, kH, kW, K, 1.0f, gy.data(), kH, gx.data(), kW, 0.0f,
                        image.data(), kW);
            benchmark::DoNotOptimize(image.data());
        }
}
BENCHMARK(BM_DirectSeparable)->RangeMultiplier(10)->Range(10, 10000)->Unit(benchmark::kMillisecond)->UseRealTime();

// Each ghost drawn over its footprint (6 sigma), clipped to the frame: the hybrid's direct path.
void BM_DirectClipped(benchmark::State& state) {
    const auto g = ghosts(static_cast<int>(state.range(0)));
    for (auto _ : state) {
        const FlareImage image = renderDirect(g, kW, kH);
        benchmark::DoNotOptimize(image.channel[0].data());
    }
}
BENCHMARK(BM_DirectClipped)->RangeMultiplier(10)->Range(10, 10000)->Unit(benchmark::kMillisecond)->UseRealTime();

// The Fourier-Bessel basis end to end (Gaussian ghosts, budget 1e-3, hybrid).
void BM_Bessel(benchmark::State& state) {
    const auto g = ghosts(static_cast<int>(state.range(0)));
    FourierSettings s;
    s.basis = Basis::Bessel;
    FourierRender r;
    for (auto _ : state) {
        r = renderFourier(g, kW, kH, s);
        benchmark::DoNotOptimize(r.image.channel[0].data());
    }
    state.counters["J"] = r.plan.n;
    state.counters["M"] = r.plan.m;
}
BENCHMARK(BM_Bessel)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();

// Not a timing: the accuracy reached on 100 ghosts with every ghost through the series (no hybrid),
// as relative L2 against drawing them directly, separable and Bessel, with and without the DC term
// (arg 1 = --drop-dc). The Bessel basis takes isotropic ghosts: these are made isotropic first.
void BM_AccuracyAgainstDirect(benchmark::State& state, Basis basis) {
    auto g = ghosts(100, 10.0, 80.0);
    if (basis == Basis::Bessel)
        for (Ghost& k : g) k.widthY = k.widthX;
    FourierSettings s;
    s.basis = basis;
    s.hybrid = false;
    s.dropDc = state.range(0) != 0;
    const FlareImage direct = renderDirect(g, kW, kH);
    FourierRender r;
    for (auto _ : state) r = renderFourier(g, kW, kH, s);
    double num = 0.0, den = 0.0, sum = 0.0, ref = 0.0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t p = 0; p < direct.pixels(); ++p) {
            const double d = double(r.image.channel[c][p]) - direct.channel[c][p];
            num += d * d;
            den += double(direct.channel[c][p]) * direct.channel[c][p];
            sum += r.image.channel[c][p];
            ref += direct.channel[c][p];
        }
    state.counters["relL2"] = std::sqrt(num / den);
    state.counters["fluxRatio"] = sum / ref;
    state.counters["N"] = r.plan.n;
    state.counters["direct"] = double(r.plan.direct);
}
BENCHMARK_CAPTURE(BM_AccuracyAgainstDirect, separable, Basis::Separable)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_AccuracyAgainstDirect, bessel, Basis::Bessel)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

} // namespace

BENCHMARK_MAIN();
