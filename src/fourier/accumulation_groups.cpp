// Grouping the Fourier-routed ghosts for accumulation and choosing, per group, a GEMM of their
// coefficient vectors or a sampling grid (gridded.h).

#include "fourier/gridded.h"
#include "fourier/plan.h"

#include <climits>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <utility>

namespace ff::fourier {

const char* toString(Accumulation a) {
    switch (a) {
    case Accumulation::Auto:
        return "auto";
    case Accumulation::Gemm:
        return "gemm";
    case Accumulation::Grid:
        return "grid";
    }
    return "?";
}

namespace {

// Rounds a ghost's term count up to a multiple of 8 (a band), at most the plan's count.
int band(int terms, int limit) {
    return std::min(limit, 8 * ((std::max(terms, 1) + 7) / 8));
}

// Relative costs (per channel) in GEMM-equivalent flops: a GEMM multiply-add is 2 flops at sgemm's
// rate; a spread sample is a multiply-add at about half that rate (4); each stencil sample also costs
// its profile value; the transform runs at a fifth of sgemm's rate, like the evaluation's (plan.cpp).
// Checked with bench_fourier's BM_Accumulate (docs/performance.md): `auto` is as fast as the faster
// method, or faster, from 100 to 100 000 ghosts.
constexpr double kSpreadFlops = 4.0, kProfileFlops = 20.0, kFftWeight = 5.0;

double gemmFlops(std::size_t count, int n, int m) {
    return static_cast<double>(count) * (8.0 * n * m + 60.0 * (n + m));
}

// Width class of a ghost on a grid: quarter octaves of its narrowest width per axis. A grid's
// spacing follows its narrowest member, so each member's stencil is at most 2^(1/4) times the least.
int quarterOctave(double w) {
    int e = 0;
    const double f = 2.0 * std::frexp(w, &e); // w = f 2^(e-1), f in [1, 2)
    return 4 * (e - 1) + (f >= 1.189207115002721) + (f >= 1.414213562373095) + (f >= 1.681792830507429);
}

// Each ghost's narrowest and widest width per axis (any channel), gathered in one pass: the
// grouping then reads these instead of ghosts scattered over memory.
struct Widths {
    std::vector<double> narrowX, narrowY, wideX, wideY;
};

// Sizes a group's grid from its members and returns the grid's estimated work.
double sizeGrid(AccumulationGroup& g, const Widths& w, const Plan& plan, double aliasError) {
    double narrowX = 1e300, narrowY = 1e300;
    for (std::size_t k : g.members) {
        narrowX = std::min(narrowX, w.narrowX[k]);
        narrowY = std::min(narrowY, w.narrowY[k]);
    }
    g.gridX = gridSamples(g.shape, g.n, narrowX, plan.periodX, aliasError);
    g.gridY = gridSamples(g.shape, g.m, narrowY, plan.periodY, aliasError);
    double spread = 0.0;
    const double hx = plan.periodX / g.gridX, hy = plan.periodY / g.gridY;
    for (std::size_t k : g.members) {
        const int sx = stencilSamples(g.shape, w.narrowX[k], hx), sy = stencilSamples(g.shape, w.narrowY[k], hy);
        spread += kSpreadFlops * sx * sy + kProfileFlops * (sx + sy);
    }
    const double cells = double(g.gridX) * g.gridY;
    const double chunks = std::ceil(double(g.members.size()) / kAccumulationChunk);
    return 3.0 * spread + chunks * 3.0 * kFftWeight * 2.5 * cells * std::log2(cells);
}

} // namespace

void groupForAccumulation(const std::vector<Ghost>& ghosts, const FourierSettings& settings, Plan& plan) {
    plan.groups.clear();
    if (plan.n == 0 || plan.m == 0) return;
    // Ghosts of one shape and the same bands: one GEMM's worth. Keys index a table (shape, band x,
    // band y); groups come out in key order, members in ghost order.
    const int bandsX = plan.n / 8 + 2, bandsY = plan.m / 8 + 2;
    std::vector<int> slot(static_cast<std::size_t>(2 * bandsX * bandsY), -1);
    std::vector<AccumulationGroup> byBands;
    // Widths and table keys per ghost in parallel (each ghost writes its own entries), then the
    // groups' members in ghost order.
    Widths w;
    for (auto* v : {&w.narrowX, &w.narrowY, &w.wideX, &w.wideY}) v->assign(ghosts.size(), 0.0);
    std::vector<int> key(ghosts.size(), -1);
    tbb::parallel_for(std::size_t(0), ghosts.size(), [&](std::size_t k) {
        if (plan.route[k] != Route::Fourier) return;
        w.narrowX[k] = narrowest(ghosts[k].widthX);
        w.narrowY[k] = narrowest(ghosts[k].widthY);
        w.wideX[k] = widest(ghosts[k].widthX);
        w.wideY[k] = widest(ghosts[k].widthY);
        const int nb = band(plan.termsX[k], plan.n), mb = band(plan.termsY[k], plan.m);
        const int shape = ghosts[k].shape == Shape::Gaussian ? 0 : 1;
        key[k] = (shape * bandsX + (nb + 7) / 8) * bandsY + (mb + 7) / 8;
    });
    for (std::size_t k = 0; k < ghosts.size(); ++k) {
        if (key[k] < 0) continue;
        int& s = slot[static_cast<std::size_t>(key[k])];
        if (s < 0) {
            s = static_cast<int>(byBands.size());
            byBands.push_back({ghosts[k].shape,
                               band(plan.termsX[k], plan.n),
                               band(plan.termsY[k], plan.m),
                               Accumulation::Gemm,
                               0,
                               0,
                               0.0,
                               0.0,
                               {}});
        }
        byBands[static_cast<std::size_t>(s)].members.push_back(k);
    }
    std::vector<std::size_t> order;
    for (int s : slot)
        if (s >= 0) order.push_back(static_cast<std::size_t>(s));
    // The grid's aliases are held to the trimmed budget (a quarter of the budget when nothing is trimmed).
    const double aliasError = settings.error * (settings.trimFraction > 0.0 ? settings.trimFraction : 0.25);
    for (std::size_t index : order) {
        AccumulationGroup& g = byBands[index];
        const bool canGrid = g.shape == Shape::Cos2 || settings.gaussianForm == GaussianForm::Periodised;
        if (canGrid && settings.accumulation != Accumulation::Gemm) {
            // On grids, the band's ghosts are split by width class, each class with its own spacing.
            std::vector<std::pair<int, int>> cls(g.members.size());
            int loX = INT_MAX, hiX = INT_MIN, loY = INT_MAX, hiY = INT_MIN;
            for (std::size_t i = 0; i < g.members.size(); ++i) {
                cls[i] = {quarterOctave(w.narrowX[g.members[i]]), quarterOctave(w.narrowY[g.members[i]])};
                loX = std::min(loX, cls[i].first), hiX = std::max(hiX, cls[i].first);
                loY = std::min(loY, cls[i].second), hiY = std::max(hiY, cls[i].second);
            }
            const int spanY = hiY - loY + 1;
            std::vector<int> classSlot(static_cast<std::size_t>(hiX - loX + 1) * spanY, -1);
            std::vector<AccumulationGroup> subs;
            for (std::size_t i = 0; i < g.members.size(); ++i) {
                int& s = classSlot[static_cast<std::size_t>(cls[i].first - loX) * spanY + (cls[i].second - loY)];
                if (s < 0) {
                    s = static_cast<int>(subs.size());
                    subs.push_back({g.shape, 0, 0, Accumulation::Grid, 0, 0, 0.0, 0.0, {}});
                }
                // A grid's cost does not grow with its terms: it keeps exactly its members' terms.
                AccumulationGroup& sub = subs[static_cast<std::size_t>(s)];
                sub.members.push_back(g.members[i]);
                sub.n = std::max(sub.n, plan.termsX[g.members[i]]);
                sub.m = std::max(sub.m, plan.termsY[g.members[i]]);
            }
            double gridWork = 0.0;
            bool huge = false; // a grid past 2^24 samples (64 MiB per channel and task): never
            for (AccumulationGroup& sub : subs) {
                gridWork += sizeGrid(sub, w, plan, aliasError);
                huge = huge || double(sub.gridX) * sub.gridY > double(1 << 24);
            }
            if (!huge && (settings.accumulation == Accumulation::Grid ||
                          gridWork < 3.0 * gemmFlops(g.members.size(), g.n, g.m))) {
                for (int s : classSlot)
                    if (s >= 0) plan.groups.push_back(std::move(subs[static_cast<std::size_t>(s)]));
                continue;
            }
        }
        plan.groups.push_back(std::move(g));
    }
    for (AccumulationGroup& g : plan.groups)
        for (std::size_t k : g.members) {
            g.widestX = std::max(g.widestX, w.wideX[k]);
            g.widestY = std::max(g.widestY, w.wideY[k]);
        }
}

} // namespace ff::fourier
