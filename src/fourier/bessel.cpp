#include "fourier/bessel.h"

#include "core/error.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "fourier/direct.h"
#include "fourier/fftw_planner.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fftw3.h>
#include <mutex>
#include <numbers>

namespace ff::fourier {

void besselSeries(double x, int count, double* out) {
    if (count <= 0) return;
    std::fill(out, out + count, 0.0);
    if (x == 0.0) {
        out[0] = 1.0;
        return;
    }
    const double big = std::max(double(count), std::abs(x));
    int start = static_cast<int>(big + 16.0 + std::sqrt(40.0 * big));
    start += start % 2; // even, so the normalisation sum ends on J0
    double next = 0.0, cur = 1e-300, norm = 0.0;
    for (int m = start; m > 0; --m) {
        const double prev = 2.0 * m / x * cur - next; // J_{m-1}
        next = cur;
        cur = prev;
        if (m - 1 < count) out[m - 1] = cur;
        if ((m - 1) % 2 == 0 && m - 1 > 0) norm += 2.0 * cur;
        if (std::abs(cur) > 1e250) { // rescale everything kept so far
            next *= 1e-250, cur *= 1e-250, norm *= 1e-250;
            for (int i = m - 1; i < count; ++i) out[i] *= 1e-250;
        }
    }
    norm += cur; // J0
    for (int i = 0; i < count; ++i) out[i] /= norm;
}

std::vector<double> besselZeros(int count) {
    std::vector<double> z(static_cast<std::size_t>(count));
    for (int j = 1; j <= count; ++j) {
        const double b = (j - 0.25) * std::numbers::pi;
        double x = b + 1.0 / (8.0 * b);                                                         // McMahon
        for (int i = 0; i < 4; ++i) x += std::cyl_bessel_j(0.0, x) / std::cyl_bessel_j(1.0, x); // Newton: J0' = -J1
        z[static_cast<std::size_t>(j - 1)] = x;
    }
    return z;
}

namespace {

// Catmull-Rom weights for fraction t.
void catmullRom(double t, double w[4]) {
    const double t2 = t * t, t3 = t2 * t;
    w[0] = 0.5 * (-t3 + 2.0 * t2 - t);
    w[1] = 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0);
    w[2] = 0.5 * (-3.0 * t3 + 4.0 * t2 + t);
    w[3] = 0.5 * (t3 - t2);
}

} // namespace

namespace {

// What the plan fixes besides the Plan: the ghosts made isotropic, the disc and its Bessel zeros.
struct BesselSetup {
    std::vector<Ghost> iso;     ///< geometric-mean width per channel
    double ox = 0.0, oy = 0.0;  ///< the disc's centre, the frame's centre (px)
    double rMax = 0.0;          ///< the frame's half-diagonal (px)
    double R0 = 0.0;            ///< the disc's radius (px)
    double h = 0.5;             ///< ring spacing (px)
    std::vector<double> lambda; ///< the first J zeros of J0
};

// Routes every ghost (culled, direct, Fourier), then J, M and the polar grid, into `p`.
BesselSetup planBessel(const std::vector<Ghost>& ghosts, int W, int H, const FourierSettings& s, Plan& p) {
    BesselSetup b;
    p.basis = Basis::Bessel;
    const std::size_t K = ghosts.size();
    p.route.assign(K, Route::Fourier);
    p.termsX.assign(K, 0);
    p.termsY.assign(K, 0);
    b.ox = 0.5 * W;
    b.oy = 0.5 * H;
    b.rMax = std::hypot(b.ox, b.oy);
    const double ox = b.ox, oy = b.oy, rMax = b.rMax;
    // Isotropic ghosts (geometric-mean sigma per channel), their distances and the routes.
    b.iso = ghosts;
    std::vector<Ghost>& iso = b.iso;
    double dMax = 0.0, sigmaMin = std::numeric_limits<double>::infinity();
    const double kSigma = std::sqrt(2.0 * std::log(1.0 / s.error)); // K sigma for the budget (Hankel tail)
    for (std::size_t k = 0; k < K; ++k) {
        const Ghost& g = ghosts[k];
        if (g.shape != Shape::Gaussian)
            throw Error(ErrorKind::Usage, "the Fourier-Bessel basis takes Gaussian ghosts only (use the Gaussian "
                                          "profile or the separable basis)");
        for (int c = 0; c < 3; ++c) iso[k].widthX[c] = iso[k].widthY[c] = std::sqrt(g.widthX[c] * g.widthY[c]);
        const double ext = iso[k].extentX();
        const bool empty = g.flux[0] == 0.0 && g.flux[1] == 0.0 && g.flux[2] == 0.0;
        if (empty || g.x + ext < 0.0 || g.x - ext > W || g.y + ext < 0.0 || g.y - ext > H)
            p.route[k] = Route::Culled;
        else if (std::hypot(g.x - ox, g.y - oy) > 1.5 * rMax)
            p.route[k] = Route::Direct;
    }
    // J: fixed, or the least that keeps the narrowest routed ghost in budget, capped at 256; a ghost
    // needing more goes direct.
    auto termsFor = [&](double sigma, double R0) {
        return static_cast<int>(std::ceil(kSigma / sigma * R0 / std::numbers::pi)) + 2;
    };
    for (std::size_t k = 0; k < K; ++k)
        if (p.route[k] == Route::Fourier) dMax = std::max(dMax, std::hypot(ghosts[k].x - ox, ghosts[k].y - oy));
    // The disc covers every ghost-to-pixel distance, and every ghost decays within it (the closed-form
    // c_j integrate the profile to infinity): f(R0) below a tenth of the budget.
    double widest = 0.0;
    for (std::size_t k = 0; k < K; ++k)
        if (p.route[k] == Route::Fourier)
            widest = std::max({widest, iso[k].widthX[0], iso[k].widthX[1], iso[k].widthX[2]});
    const double R0 = std::max(dMax + rMax, widest * std::sqrt(2.0 * std::log(10.0 / s.error))) + 1.0;
    b.R0 = R0;
    const int cap = s.fixedN > 0 ? s.fixedN : 256;
    for (std::size_t k = 0; k < K; ++k) {
        if (p.route[k] != Route::Fourier) continue;
        const double sg = std::min({iso[k].widthX[0], iso[k].widthX[1], iso[k].widthX[2]});
        if (s.hybrid && termsFor(sg, R0) > cap)
            p.route[k] = Route::Direct;
        else
            sigmaMin = std::min(sigmaMin, sg);
    }
    const int J = std::isfinite(sigmaMin) ? (s.fixedN > 0 ? s.fixedN : std::min(cap, termsFor(sigmaMin, R0))) : 0;
    b.lambda = besselZeros(J);
    const double kMax = J > 0 ? b.lambda.back() / R0 : 0.0;
    const double x = kMax * std::min(dMax, rMax);
    const int M = J > 0 ? (s.fixedM > 0 ? s.fixedM : static_cast<int>(std::ceil(x + 4.0 * std::cbrt(x) + 12.0))) : 0;
    p.n = J;
    p.m = M;
    p.periodX = p.periodY = R0;
    for (std::size_t k = 0; k < K; ++k) {
        p.fourier += p.route[k] == Route::Fourier;
        p.direct += p.route[k] == Route::Direct;
        p.culled += p.route[k] == Route::Culled;
    }
    const int rings = static_cast<int>(std::ceil(rMax / b.h)) + 3;
    // Even (ring -1 is ring 1 half a turn away), at most 0.75 px apart on the outer ring, above 2M.
    const int angles = 2 * fftFriendly(std::max(M + 1, static_cast<int>(std::ceil(std::numbers::pi * rMax / 0.75))));
    p.polarRings = rings;
    p.polarAngles = angles;
    p.reason = "Fourier-Bessel on a disc of radius " + text::fixed(R0, 0) + " px, J " + std::to_string(J) + " x M " +
               std::to_string(M) + ", polar grid " + std::to_string(rings) + " x " + std::to_string(angles) +
               ", budget " + text::roundTrip(s.error);
    return b;
}

using Channels = std::array<std::vector<double>, 3>;

// The coefficients a_jm, b_jm (J x M per channel) of the routed ghosts: rows j in parallel, ghosts
// in order within a row.
void accumulateBessel(const BesselSetup& bs, const Plan& p, Channels& a, Channels& b) {
    const int J = p.n, M = p.m;
    const double R0 = bs.R0;
    std::vector<std::size_t> routed;
    for (std::size_t k = 0; k < p.route.size(); ++k)
        if (p.route[k] == Route::Fourier) routed.push_back(k);
    for (int c = 0; c < 3; ++c) a[c].assign(static_cast<std::size_t>(J) * M, 0.0), b[c] = a[c];
    std::vector<double> normJ1(static_cast<std::size_t>(J));
    for (int j = 0; j < J; ++j) {
        const double j1 = std::cyl_bessel_j(1.0, bs.lambda[static_cast<std::size_t>(j)]);
        normJ1[static_cast<std::size_t>(j)] = R0 * R0 * j1 * j1;
    }
    tbb::parallel_for(0, J, [&](int j) {
        const double kj = bs.lambda[static_cast<std::size_t>(j)] / R0;
        std::vector<double> jm(static_cast<std::size_t>(M));
        for (std::size_t k : routed) {
            const Ghost& g = bs.iso[k];
            const double dx = g.x - bs.ox, dy = g.y - bs.oy, d = std::hypot(dx, dy), th = std::atan2(dy, dx);
            besselSeries(kj * d, M, jm.data());
            for (int c = 0; c < 3; ++c) {
                const double sg = g.widthX[c];
                const double alpha = g.flux[c] / (2.0 * std::numbers::pi * sg * sg);
                // c_j of exp(-rho^2 / 2 sigma^2): its Hankel transform sigma^2 exp(-k^2 sigma^2 / 2), times 2 /
                // (R0^2 J1^2).
                const double cj =
                    2.0 * sg * sg * std::exp(-0.5 * kj * kj * sg * sg) / normJ1[static_cast<std::size_t>(j)];
                double* ar = &a[c][static_cast<std::size_t>(j) * M];
                double* br = &b[c][static_cast<std::size_t>(j) * M];
                for (int m = 0; m < M; ++m) {
                    const double v = alpha * cj * (m == 0 ? 1.0 : 2.0) * jm[static_cast<std::size_t>(m)];
                    ar[m] += v * std::cos(m * th);
                    br[m] += v * std::sin(m * th);
                }
            }
        }
    });
}

// The series on the polar grid, per channel (rings x angles): rings in parallel, each a radial
// contraction and one c2r FFT.
std::array<std::vector<float>, 3> polarGrid(const BesselSetup& bs, const Plan& p, const Channels& a,
                                            const Channels& b) {
    const int J = p.n, M = p.m, rings = p.polarRings, angles = p.polarAngles;
    const int half = angles / 2 + 1;
    fftwf_plan plan;
    std::vector<fftwf_complex> probeIn(static_cast<std::size_t>(half));
    std::vector<float> probeOut(static_cast<std::size_t>(angles));
    {
        std::lock_guard<std::mutex> lock(fftwPlannerMutex());
        plan = fftwf_plan_dft_c2r_1d(angles, probeIn.data(), probeOut.data(), FFTW_ESTIMATE | FFTW_UNALIGNED);
    }
    std::array<std::vector<float>, 3> rings3;
    for (auto& v : rings3) v.assign(static_cast<std::size_t>(rings) * angles, 0.0f);
    tbb::parallel_for(0, rings, [&](int i) {
        const double rr = i * bs.h;
        std::vector<double> jm(static_cast<std::size_t>(M));
        std::vector<std::array<double, 2>> acc(static_cast<std::size_t>(3 * M), {0.0, 0.0});
        for (int j = 0; j < J; ++j) {
            besselSeries(bs.lambda[static_cast<std::size_t>(j)] / bs.R0 * rr, M, jm.data());
            for (int c = 0; c < 3; ++c) {
                const double* ar = &a[c][static_cast<std::size_t>(j) * M];
                const double* br = &b[c][static_cast<std::size_t>(j) * M];
                for (int m = 0; m < M; ++m) {
                    acc[static_cast<std::size_t>(c * M + m)][0] += ar[m] * jm[static_cast<std::size_t>(m)];
                    acc[static_cast<std::size_t>(c * M + m)][1] += br[m] * jm[static_cast<std::size_t>(m)];
                }
            }
        }
        std::vector<fftwf_complex> in(static_cast<std::size_t>(half));
        for (int c = 0; c < 3; ++c) {
            for (auto& e : in) e[0] = e[1] = 0.0f;
            // c2r: out = X0 + 2 Re sum X_m e^{i m theta}; X_m = (a - i b) / 2 gives a cos + b sin.
            for (int m = 0; m < M && m < half; ++m) {
                const auto& v = acc[static_cast<std::size_t>(c * M + m)];
                const double f = m == 0 ? 1.0 : 0.5;
                in[static_cast<std::size_t>(m)][0] = static_cast<float>(f * v[0]);
                in[static_cast<std::size_t>(m)][1] = static_cast<float>(-f * v[1]);
            }
            fftwf_execute_dft_c2r(plan, in.data(), &rings3[c][static_cast<std::size_t>(i) * angles]);
        }
    });
    {
        std::lock_guard<std::mutex> lock(fftwPlannerMutex());
        fftwf_destroy_plan(plan);
    }
    return rings3;
}

// The pixels from the polar grid: bicubic, periodic in theta.
void resamplePolar(const BesselSetup& bs, const Plan& p, const std::array<std::vector<float>, 3>& rings3,
                   FlareImage& image) {
    const int W = image.width, H = image.height, rings = p.polarRings, angles = p.polarAngles;
    tbb::parallel_for(0, H, [&](int y) {
        for (int xpx = 0; xpx < W; ++xpx) {
            const double dx = xpx + 0.5 - bs.ox, dy = y + 0.5 - bs.oy;
            const double pr = std::hypot(dx, dy) / bs.h;
            double th = std::atan2(dy, dx);
            if (th < 0.0) th += 2.0 * std::numbers::pi;
            const double pt = th / (2.0 * std::numbers::pi) * angles;
            const int ir = static_cast<int>(std::floor(pr)), it = static_cast<int>(std::floor(pt));
            double wr[4], wt[4];
            catmullRom(pr - ir, wr);
            catmullRom(pt - it, wt);
            for (int c = 0; c < 3; ++c) {
                double v = 0.0;
                for (int u = 0; u < 4; ++u) {
                    // Ring -1 is ring 1 at the opposite angle; beyond the grid's last ring, the last ring.
                    int ring = ir - 1 + u;
                    int shift = 0;
                    if (ring < 0) ring = -ring, shift = angles / 2;
                    ring = std::min(ring, rings - 1);
                    const float* row = &rings3[c][static_cast<std::size_t>(ring) * angles];
                    double rv = 0.0;
                    for (int q = 0; q < 4; ++q) rv += wt[q] * row[((it - 1 + q + shift) % angles + angles) % angles];
                    v += wr[u] * rv;
                }
                image.channel[c][static_cast<std::size_t>(y) * W + xpx] = static_cast<float>(v);
            }
        }
    });
}

} // namespace

FourierRender renderBessel(const std::vector<Ghost>& ghosts, int W, int H, const FourierSettings& s) {
    auto t = Clock::now();
    FourierRender r;
    const BesselSetup setup = planBessel(ghosts, W, H, s, r.plan);
    r.seconds.plan = lap(t);
    r.image = FlareImage(W, H);
    if (r.plan.n > 0 && r.plan.fourier > 0) {
        Channels a, b;
        accumulateBessel(setup, r.plan, a, b);
        r.seconds.accumulate = lap(t);
        resamplePolar(setup, r.plan, polarGrid(setup, r.plan, a, b), r.image);
        r.seconds.evaluate = lap(t);
    }
    std::vector<std::size_t> direct;
    for (std::size_t k = 0; k < ghosts.size(); ++k)
        if (r.plan.route[k] == Route::Direct) direct.push_back(k);
    drawDirect(setup.iso, direct, r.image);
    r.seconds.direct = lap(t);
    return r;
}

} // namespace ff::fourier
