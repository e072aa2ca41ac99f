#include "fourier/aggregate.h"

#include "fourier/blas_threads.h"
#include "fourier/gridded.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cblas.h>
#include <cmath>
#include <numbers>

namespace ff::fourier {

namespace {

// Coefficients g_0..g_{count-1} of one profile. The periodised Gaussian uses the recurrence
// exp(-c (i+1)^2) = exp(-c i^2) exp(-c (2i + 1)); the other forms evaluate each term.
void profileCoefficients(Shape s, double width, double period, GaussianForm form, int count, double* out) {
    if (s == Shape::Gaussian && form == GaussianForm::Periodised) {
        const double w = 2.0 * std::numbers::pi / period;
        const double c = 0.5 * w * w * width * width; // b^2 = c i^2
        const double scale = width * std::sqrt(2.0 * std::numbers::pi) / period;
        double term = 1.0, step = std::exp(-c), stepStep = std::exp(-2.0 * c);
        for (int i = 0; i < count; ++i) {
            out[i] = scale * term;
            term *= step;
            step *= stepStep;
        }
        return;
    }
    for (int i = 0; i < count; ++i) out[i] = coefficient(s, i, width, period, form);
}

// cos(i w x), sin(i w x) for i < count by rotation (float64; drift ~1e-16 i).
void phases(double x, double w, int count, double* c, double* s) {
    const double c1 = std::cos(w * x), s1 = std::sin(w * x);
    double cr = 1.0, sr = 0.0;
    for (int i = 0; i < count; ++i) {
        c[i] = cr;
        s[i] = sr;
        const double nc = cr * c1 - sr * s1;
        sr = sr * c1 + cr * s1;
        cr = nc;
    }
}

} // namespace

Coefficients Coefficients::zeros(const Plan& plan) {
    Coefficients co;
    co.n = plan.n;
    co.m = plan.m;
    co.periodX = plan.periodX;
    co.periodY = plan.periodY;
    for (auto& z : co.z) z.assign(static_cast<std::size_t>(4) * co.n * co.m, 0.0);
    return co;
}

Coefficients accumulate(const std::vector<Ghost>& ghosts, const Plan& plan, const FourierSettings& settings) {
    Coefficients co = Coefficients::zeros(plan);
    if (co.n == 0 || co.m == 0) return co;

    const double wx = 2.0 * std::numbers::pi / co.periodX, wy = 2.0 * std::numbers::pi / co.periodY;
    // One task per (group, chunk of ghosts) on a grid (all channels in one pass), or per (channel,
    // group, chunk) for a GEMM, run in parallel, each with its own grid or single-threaded GEMM (a
    // long inner dimension and a small output); the tasks' results are then added in task order, so
    // the sums do not depend on the thread count.
    struct Task {
        int channel; // -1: every channel (grid)
        const AccumulationGroup* group;
        std::size_t first, count;
        std::array<std::vector<double>, 3> result; // per channel, 2n x 2m of the group: [[A, B], [C, D]]
    };
    std::vector<Task> tasks;
    for (const AccumulationGroup& group : plan.groups)
        for (std::size_t first = 0; first < group.members.size(); first += kAccumulationChunk) {
            const std::size_t count = std::min(kAccumulationChunk, group.members.size() - first);
            if (group.method == Accumulation::Grid)
                tasks.push_back({-1, &group, first, count, {}});
            else
                for (int c = 0; c < 3; ++c) tasks.push_back({c, &group, first, count, {}});
        }
    const SingleThreadedBlas blasOnOneThread;
    tbb::parallel_for(std::size_t(0), tasks.size(), [&](std::size_t t) {
        Task& task = tasks[t];
        const AccumulationGroup& group = *task.group;
        if (task.channel < 0) {
            task.result = accumulateGridded(ghosts, group, task.first, task.count, co.periodX, co.periodY);
            return;
        }
        const int c = task.channel, nb = group.n, mb = group.m;
        std::vector<double> coef(static_cast<std::size_t>(std::max(nb, mb))), cs(coef.size()), sn(coef.size());
        std::vector<float> U(task.count * 2 * nb), V(task.count * 2 * mb);
        for (std::size_t r = 0; r < task.count; ++r) {
            const Ghost& g = ghosts[group.members[task.first + r]];
            const double alpha = g.peak(c);
            profileCoefficients(g.shape, g.widthX[c], co.periodX, settings.gaussianForm, nb, coef.data());
            phases(g.x, wx, nb, cs.data(), sn.data());
            float* u = &U[r * 2 * nb];
            for (int i = 0; i < nb; ++i) {
                u[i] = static_cast<float>(alpha * coef[i] * cs[i]);
                u[nb + i] = static_cast<float>(alpha * coef[i] * sn[i]);
            }
            profileCoefficients(g.shape, g.widthY[c], co.periodY, settings.gaussianForm, mb, coef.data());
            phases(g.y, wy, mb, cs.data(), sn.data());
            float* v = &V[r * 2 * mb];
            for (int j = 0; j < mb; ++j) {
                v[j] = static_cast<float>(coef[j] * cs[j]);
                v[mb + j] = static_cast<float>(coef[j] * sn[j]);
            }
        }
        std::vector<float> product(static_cast<std::size_t>(4) * nb * mb, 0.0f);
        cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, 2 * nb, 2 * mb, static_cast<int>(task.count), 1.0f,
                    U.data(), 2 * nb, V.data(), 2 * mb, 0.0f, product.data(), 2 * mb);
        task.result[c].assign(product.begin(), product.end());
    });
    // Each chunk's blocks into the full matrices, in float64, in task order.
    for (const Task& task : tasks) {
        const int nb = task.group->n, mb = task.group->m;
        for (int c = 0; c < 3; ++c) {
            if (task.result[c].empty()) continue;
            for (int half = 0; half < 2; ++half)
                for (int i = 0; i < nb; ++i)
                    for (int side = 0; side < 2; ++side)
                        for (int j = 0; j < mb; ++j)
                            co.at(c, half * co.n + i, side * co.m + j) +=
                                task.result[c][static_cast<std::size_t>(half * nb + i) * 2 * mb + side * mb + j];
        }
    }
    if (settings.dropDc)
        for (int c = 0; c < 3; ++c) co.at(c, 0, 0) = 0.0;
    return co;
}

} // namespace ff::fourier
