#include "fourier/plan.h"

#include "core/text.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ff::fourier {

const char* toString(Evaluation e) {
    switch (e) {
    case Evaluation::Auto:
        return "auto";
    case Evaluation::Matrix:
        return "matrix";
    case Evaluation::Fft:
        return "fft";
    }
    return "?";
}

int fftFriendly(int n) {
    for (int k = std::max(n, 1);; ++k) {
        int r = k;
        for (int p : {2, 3, 5})
            while (r % p == 0) r /= p;
        if (r == 1) return k;
    }
}

std::string Plan::describe() const {
    if (basis == Basis::Bessel)
        return reason + "; ghosts: " + std::to_string(fourier) + " Fourier-Bessel, " + std::to_string(direct) +
               " direct, " + std::to_string(culled) + " culled";
    std::string s = "period " + text::fixed(periodX, 0) + "x" + text::fixed(periodY, 0) + " px, N " +
                    std::to_string(n) + " x M " + std::to_string(m) + ", " + toString(evaluation) +
                    " evaluation; ghosts: " + std::to_string(fourier) + " Fourier, " + std::to_string(direct) +
                    " direct, " + std::to_string(culled) + " culled" +
                    (wide ? ", " + std::to_string(wide) + " on a coarse level" : std::string());
    if (!reason.empty()) s += " (" + reason + ")";
    std::size_t gridGroups = 0, gridGhosts = 0;
    for (const AccumulationGroup& g : groups)
        if (g.method == Accumulation::Grid) ++gridGroups, gridGhosts += g.members.size();
    if (gridGroups > 0)
        s += "; accumulated on grids: " + std::to_string(gridGhosts) + " ghosts in " + std::to_string(gridGroups) +
             " of " + std::to_string(groups.size()) + " groups";
    return s;
}

namespace {

// Distance beyond which a periodic copy of the ghost adds less than a tenth of the budget (relative to
// its peak): the padding. cos^2 has compact support.
double padExtent(const Ghost& g, double width, double error) {
    return g.shape == Shape::Gaussian ? width * std::sqrt(2.0 * std::log(10.0 / error)) : width;
}

// Estimated work (3 channels) of each route, in GEMM-equivalent flops. The FFT's nominal
// 2.5 P log2 P flops of a real inverse transform ran at about a fifth of sgemm's rate
// (bench_fourier, docs/performance.md): weighted by 5.
double evaluationFlops(int n, int m, int w, int h, double tx, double ty, Evaluation e) {
    if (n == 0) return 0.0;
    const double matrix = 3.0 * (8.0 * n * m * h + 4.0 * n * double(w) * h);
    const double fft = 3.0 * 5.0 * 2.5 * tx * ty * std::log2(tx * ty);
    if (e == Evaluation::Matrix) return matrix;
    if (e == Evaluation::Fft) return fft;
    return std::min(matrix, fft);
}

} // namespace

namespace {

// Per shape (0 Gaussian, 1 cos^2), the spectral cut-off of the error budget and of the trimmed
// budget (error x trimFraction; 0 without trimming), computed only for the shapes present (the cos^2
// one tabulates its spectrum once).
struct Cutoffs {
    double full[2] = {0.0, 0.0}, trim[2] = {0.0, 0.0};
};
Cutoffs shapeCutoffs(const std::vector<Ghost>& ghosts, const FourierSettings& s) {
    bool present[2] = {false, false};
    for (const Ghost& g : ghosts) present[g.shape == Shape::Gaussian ? 0 : 1] = true;
    Cutoffs c;
    for (int sh = 0; sh < 2; ++sh) {
        if (!present[sh]) continue;
        const Shape shape = sh == 0 ? Shape::Gaussian : Shape::Cos2;
        c.full[sh] = spectralCutoff(shape, s.error);
        if (s.trimFraction > 0.0) c.trim[sh] = spectralCutoff(shape, s.error * s.trimFraction);
    }
    return c;
}

// The period along one axis: the one fixed by the settings, else the largest need (at least the
// frame's side, at most the cap) rounded up to a size the FFT handles fast.
double periodFor(double need, double fixed, double cap) {
    return fixed > 0.0 ? fixed : fftFriendly(static_cast<int>(std::ceil(std::min(need, cap))));
}

// Each ghost's route before the period is known: culled (no flux, or wholly off the frame), Wide
// (its copies on a period within the cap would reach the frame) or Fourier; its need, the period it
// asks for along x and y (its distance to the frame's far side plus its padded extent), and the area
// of its box on the frame. In parallel: each ghost writes only its own entries.
void routeGhosts(const std::vector<Ghost>& ghosts, int W, int H, const FourierSettings& s, double cap,
                 std::vector<Route>& route, std::vector<double>& needX, std::vector<double>& needY,
                 std::vector<double>& boxArea) {
    const std::size_t K = ghosts.size();
    tbb::parallel_for(std::size_t(0), K, [&](std::size_t k) {
        const Ghost& g = ghosts[k];
        const double ex = g.extentX(), ey = g.extentY();
        const bool empty = g.flux[0] == 0.0 && g.flux[1] == 0.0 && g.flux[2] == 0.0;
        if (empty || g.x + ex < 0.0 || g.x - ex > W || g.y + ey < 0.0 || g.y - ey > H) {
            route[k] = Route::Culled;
            return;
        }
        const double px = padExtent(g, widest(g.widthX), s.error), py = padExtent(g, widest(g.widthY), s.error);
        needX[k] = std::max(std::max(g.x, W - g.x) + px, 2.0 * px);
        needY[k] = std::max(std::max(g.y, H - g.y) + py, 2.0 * py);
        boxArea[k] = (std::min(double(W), g.x + ex) - std::max(0.0, g.x - ex) + 1.0) *
                     (std::min(double(H), g.y + ey) - std::max(0.0, g.y - ey) + 1.0);
        const double limitX = s.fixedPeriodX > 0.0 ? s.fixedPeriodX : cap,
                     limitY = s.fixedPeriodY > 0.0 ? s.fixedPeriodY : cap;
        // A ghost whose copies would reach the frame goes to a coarser level, hybrid or not.
        if (needX[k] > limitX || needY[k] > limitY) route[k] = Route::Wide;
    });
}

} // namespace

Plan choosePlan(const std::vector<Ghost>& ghosts, int W, int H, const FourierSettings& s) {
    Plan p;
    const std::size_t K = ghosts.size();
    p.route.assign(K, Route::Fourier);
    p.termsX.assign(K, 0);
    p.termsY.assign(K, 0);
    std::vector<double> needX(K, 0.0), needY(K, 0.0), boxArea(K, 0.0);
    const double cap = s.periodCap * std::max(W, H);
    routeGhosts(ghosts, W, H, s, cap, p.route, needX, needY, boxArea);
    // The period: the largest need of the ghosts still on the Fourier route.
    double tx = W, ty = H;
    for (std::size_t k = 0; k < K; ++k)
        if (p.route[k] == Route::Fourier) tx = std::max(tx, needX[k]), ty = std::max(ty, needY[k]);
    p.periodX = periodFor(tx, s.fixedPeriodX, cap);
    p.periodY = periodFor(ty, s.fixedPeriodY, cap);

    // Terms each ghost needs (its narrowest channel decides), and what it keeps when trimmed.
    std::vector<int> needN(K, 0), needM(K, 0), trimN(K, 0), trimM(K, 0);
    const Cutoffs cutoffs = shapeCutoffs(ghosts, s);
    const double(&cut)[2] = cutoffs.full;
    const double(&trimCut)[2] = cutoffs.trim;
    tbb::parallel_for(std::size_t(0), K, [&](std::size_t k) {
        if (p.route[k] != Route::Fourier) return;
        const Ghost& g = ghosts[k];
        const int sh = g.shape == Shape::Gaussian ? 0 : 1;
        needN[k] = termsForCutoff(cut[sh], narrowest(g.widthX), p.periodX);
        needM[k] = termsForCutoff(cut[sh], narrowest(g.widthY), p.periodY);
        trimN[k] = s.trimFraction > 0.0 ? termsForCutoff(trimCut[sh], narrowest(g.widthX), p.periodX)
                                        : std::numeric_limits<int>::max();
        trimM[k] = s.trimFraction > 0.0 ? termsForCutoff(trimCut[sh], narrowest(g.widthY), p.periodY)
                                        : std::numeric_limits<int>::max();
    });
    int maxN = 0, maxM = 0;
    for (std::size_t k = 0; k < K; ++k) maxN = std::max(maxN, needN[k]), maxM = std::max(maxM, needM[k]);
    auto mFor = [&](int n) {
        return s.fixedM > 0 ? s.fixedM
               : n == 0     ? 0
                            : std::max(1, static_cast<int>(std::ceil(n * p.periodY / p.periodX)));
    };
    auto cost = [&](int n) {
        const int m = mFor(n);
        double c = evaluationFlops(n, m, W, H, p.periodX, p.periodY, s.evaluation);
        for (std::size_t k = 0; k < K; ++k) {
            if (p.route[k] == Route::Culled || p.route[k] == Route::Wide) continue;
            if (p.route[k] == Route::Fourier && needN[k] <= n && needM[k] <= m)
                c += 3.0 * (8.0 * std::min(n, trimN[k]) * std::min(m, trimM[k]) + 60.0 * (n + m));
            else
                c += 3.0 * (2.0 * boxArea[k] + 80.0 * std::sqrt(boxArea[k]));
        }
        return c;
    };
    constexpr int kMaxTerms = 1024;
    if (s.fixedN > 0) {
        p.n = s.fixedN;
        p.reason = "N fixed by the caller";
    } else if (!s.hybrid) {
        p.n = std::min(kMaxTerms, std::max(maxN, static_cast<int>(std::ceil(maxM * p.periodX / p.periodY))));
        p.reason = "every ghost through Fourier: N from the narrowest ghost, budget " + text::roundTrip(s.error);
    } else {
        double best = cost(0);
        for (int n : {8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512}) {
            const double c = cost(n);
            if (c < best) best = c, p.n = n;
        }
        p.reason = "least estimated work for budget " + text::roundTrip(s.error);
    }
    p.m = mFor(p.n);
    p.estimatedGflop = cost(p.n) * 1e-9;
    p.evaluation = s.evaluation;
    if (p.evaluation == Evaluation::Auto)
        p.evaluation = evaluationFlops(p.n, p.m, W, H, p.periodX, p.periodY, Evaluation::Fft) <
                               evaluationFlops(p.n, p.m, W, H, p.periodX, p.periodY, Evaluation::Matrix)
                           ? Evaluation::Fft
                           : Evaluation::Matrix;
    for (std::size_t k = 0; k < K; ++k) {
        if (p.route[k] == Route::Fourier && s.hybrid && (p.n == 0 || needN[k] > p.n || needM[k] > p.m))
            p.route[k] = Route::Direct;
        if (p.route[k] == Route::Fourier) {
            p.termsX[k] = std::min(p.n, trimN[k]);
            p.termsY[k] = std::min(p.m, trimM[k]);
        }
        p.fourier += p.route[k] == Route::Fourier;
        p.direct += p.route[k] == Route::Direct;
        p.culled += p.route[k] == Route::Culled;
        p.wide += p.route[k] == Route::Wide;
    }
    groupForAccumulation(ghosts, s, p);
    return p;
}

} // namespace ff::fourier
