#include "fourier/evaluate.h"

#include "core/error.h"
#include "fourier/blas_threads.h"
#include "fourier/fftw_planner.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cblas.h>
#include <cmath>
#include <complex>
#include <fftw3.h>
#include <memory>
#include <mutex>
#include <numbers>

namespace ff::fourier {

namespace {

// Rows of the frame per evaluation task.
constexpr int kRowBlock = 64;

void evaluateMatrix(const Coefficients& z, FlareImage& image, Write write) {
    const int n = z.n, m = z.m, W = image.width, H = image.height;
    const std::vector<float> X = seriesBasis(n, W, z.periodX), Y = seriesBasis(m, H, z.periodY);
    std::array<std::vector<float>, 3> Z;
    for (int c = 0; c < 3; ++c) Z[c].assign(z.z[c].begin(), z.z[c].end());
    // Tasks of (channel, block of rows), each with single-threaded GEMMs on its own thread:
    // T (2N x h) = Z (2N x 2M) Y[:, rows] (2M x h); image[rows] (h x W) = T^T X (2N x W).
    const int blocks = (H + kRowBlock - 1) / kRowBlock;
    const SingleThreadedBlas blasOnOneThread;
    tbb::parallel_for(0, 3 * blocks, [&](int task) {
        const int c = task / blocks, first = task % blocks * kRowBlock, rows = std::min(kRowBlock, H - first);
        std::vector<float> T(static_cast<std::size_t>(2) * n * rows);
        cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, 2 * n, rows, 2 * m, 1.0f, Z[c].data(), 2 * m,
                    Y.data() + first, H, 0.0f, T.data(), rows);
        cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, rows, W, 2 * n, 1.0f, T.data(), rows, X.data(), W,
                    write == Write::Add ? 1.0f : 0.0f, image.channel[c].data() + static_cast<std::size_t>(first) * W,
                    W);
    });
}

void evaluateFft(const Coefficients& z, FlareImage& image, Write write) {
    const int px = static_cast<int>(std::lround(z.periodX)), py = static_cast<int>(std::lround(z.periodY));
    if (std::abs(px - z.periodX) > 1e-9 || std::abs(py - z.periodY) > 1e-9)
        throw Error(ErrorKind::Usage, "the FFT evaluation needs whole-pixel periods");
    if (px < image.width || py < image.height)
        throw Error(ErrorKind::Usage, "the FFT evaluation needs periods of at least the frame");
    const int hx = px / 2 + 1;
    const std::size_t inSize = static_cast<std::size_t>(py) * hx, outSize = static_cast<std::size_t>(py) * px;
    std::array<FftwArray<fftwf_complex>, 3> in;
    std::array<FftwArray<float>, 3> out;
    for (int c = 0; c < 3; ++c) {
        in[c] = fftwArray<fftwf_complex>(inSize);
        out[c] = fftwArray<float>(outSize);
        if (!in[c] || !out[c]) throw Error(ErrorKind::Runtime, "out of memory for the FFT evaluation");
    }
    fftwf_plan plan;
    {
        std::lock_guard<std::mutex> lock(fftwPlannerMutex());
        plan = fftwf_plan_dft_c2r_2d(py, px, in[0].get(), out[0].get(), FFTW_ESTIMATE);
    }
    if (!plan) throw Error(ErrorKind::Runtime, "FFTW could not plan the evaluation");
    const double wx = 2.0 * std::numbers::pi / z.periodX, wy = 2.0 * std::numbers::pi / z.periodY;
    tbb::parallel_for(0, 3, [&](int c) {
        using C = std::complex<double>;
        fftwf_complex* dst = in[c].get();
        std::fill_n(&dst[0][0], 2 * inSize, 0.0f);
        // Pixel centres sit on whole pixels of the period grid, so a term of frequency (n, m) is seen
        // at (n mod Px, m mod Py). The c2r transform adds the conjugate mirror of every stored
        // entry: storing G / 2 in the half plane 0 < kx < Px / 2 gives Re(G e). The columns kx = 0
        // and kx = Px / 2 mirror onto themselves and are made Hermitian: (G(r) + conj G(-r)) / 2.
        std::vector<C> column0(static_cast<std::size_t>(py), C(0.0, 0.0)), columnNyquist(column0);
        auto add = [&](int row, int n, C v) {
            fftwf_complex& e = dst[static_cast<std::size_t>(row) * hx + n];
            e[0] += static_cast<float>(v.real());
            e[1] += static_cast<float>(v.imag());
        };
        auto term = [&](long long kx, long long ky, C g) {
            const int x = static_cast<int>(((kx % px) + px) % px), y = static_cast<int>(((ky % py) + py) % py);
            if (x == 0)
                column0[static_cast<std::size_t>(y)] += g;
            else if (2 * x == px)
                columnNyquist[static_cast<std::size_t>(y)] += g;
            else if (2 * x < px)
                add(y, x, 0.5 * g);
            else
                add((py - y) % py, px - x, 0.5 * std::conj(g));
        };
        for (int n = 0; n < z.n; ++n)
            for (int m = 0; m < z.m; ++m) {
                const double A = z.at(c, n, m), B = z.at(c, n, z.m + m), Cc = z.at(c, z.n + n, m),
                             D = z.at(c, z.n + n, z.m + m);
                const double k = (n == 0 ? 1.0 : 2.0) * (m == 0 ? 1.0 : 2.0) * sinc(0.5 * n * wx) * sinc(0.5 * m * wy);
                // I = Re sum [F+ e^{i(a + b)} + F- e^{i(a - b)}], a = n wx x, b = m wy y, at pixel centres.
                term(n, m, 0.5 * k * C(A - D, -(B + Cc)) * std::polar(1.0, 0.5 * (n * wx + m * wy)));
                term(n, -m, 0.5 * k * C(A + D, B - Cc) * std::polar(1.0, 0.5 * (n * wx - m * wy)));
            }
        for (int r = 0; r < py; ++r) {
            const std::size_t i = static_cast<std::size_t>(r), mirror = static_cast<std::size_t>((py - r) % py);
            add(r, 0, 0.5 * (column0[i] + std::conj(column0[mirror])));
            if (px % 2 == 0) add(r, px / 2, 0.5 * (columnNyquist[i] + std::conj(columnNyquist[mirror])));
        }
        fftwf_execute_dft_c2r(plan, dst, out[c].get());
        for (int y = 0; y < image.height; ++y) {
            const float* src = out[c].get() + static_cast<std::size_t>(y) * px;
            float* row = image.channel[c].data() + static_cast<std::size_t>(y) * image.width;
            if (write == Write::Add)
                for (int x = 0; x < image.width; ++x) row[x] += src[x];
            else
                std::copy_n(src, image.width, row);
        }
    });
    std::lock_guard<std::mutex> lock(fftwPlannerMutex());
    fftwf_destroy_plan(plan);
}

} // namespace

std::vector<float> seriesBasis(int terms, int pixels, double period) {
    std::vector<float> b(static_cast<std::size_t>(2) * terms * pixels);
    const double w = 2.0 * std::numbers::pi / period;
    for (int n = 0; n < terms; ++n) {
        const double k = (n == 0 ? 1.0 : 2.0) * sinc(0.5 * n * w);
        float* c = &b[static_cast<std::size_t>(n) * pixels];
        float* s = &b[static_cast<std::size_t>(terms + n) * pixels];
        for (int i = 0; i < pixels; ++i) {
            // The phase reduced modulo 2 pi in float64 before the float32 store.
            const double phase = std::fmod(n * w * (i + 0.5), 2.0 * std::numbers::pi);
            c[i] = static_cast<float>(k * std::cos(phase));
            s[i] = static_cast<float>(k * std::sin(phase));
        }
    }
    return b;
}

void evaluate(const Coefficients& z, Evaluation method, FlareImage& image, Write write) {
    if (z.n == 0 || z.m == 0) {
        if (write == Write::Replace)
            for (auto& ch : image.channel) std::fill(ch.begin(), ch.end(), 0.0f);
        return;
    }
    if (method == Evaluation::Fft)
        evaluateFft(z, image, write);
    else
        evaluateMatrix(z, image, write);
}

} // namespace ff::fourier
