#include "fourier/gridded.h"

#include "core/error.h"
#include "fourier/fftw_planner.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>

namespace ff::fourier {

namespace {

// A Gaussian is sampled out to 4.5 sigma: beyond holds erfc(4.5) ~ 2e-10 of its squared norm
// (a relative L2 error of 1.4e-5).
constexpr double kGaussianReach = 4.5;

// The nearest alias lies beyond this multiple of the shape's spectral cut-off x* at the trimmed
// budget, so the aliases' share of a ghost's squared norm is at most its trimmed tail's: the alias
// error is bounded by the trimming error. A trimmed ghost keeps n >= x* T / (2 pi width) + 1 terms,
// so G >= 2n + 1 already puts every alias of a kept term there; the margin matters when the caller
// fixes N below a ghost's need.
constexpr double kAliasMargin = 1.0;

double reach(Shape s, double width) {
    return s == Shape::Gaussian ? kGaussianReach * width : width;
}

// The six axes of one ghost (x and y of each channel) are sampled together: their recurrences are
// independent, so the processor overlaps them instead of waiting on one chain at a time.
constexpr int kAxes = 6;
// Stencil rows are spread in whole groups of this many samples; the samples past an axis's reach
// that this adds are the profile's own (tiny) values, or zeros outside a cos^2's support.
constexpr int kLanes = 4;

int roundUpToLanes(int n) {
    return (n + kLanes - 1) / kLanes * kLanes;
}

// One ghost's stencils: per axis (x of channels 0-2, then y of channels 0-2) the index in [0, G)
// of its first sample and the samples within reach; `values` holds kAxes rows of `rowLength`
// samples.
struct GhostStencil {
    std::array<int, kAxes> start{}, count{};
};

// floor and ceil to integers inline (std::floor is a library call on baseline x86-64).
long long floorToInt(double x) {
    const auto i = static_cast<long long>(x);
    return i - (x < static_cast<double>(i));
}
long long ceilToInt(double x) {
    const auto i = static_cast<long long>(x);
    return i + (x > static_cast<double>(i));
}

GhostStencil sampleGhost(Shape shape, const Ghost& g, double hx, double hy, int gx, int gy, int rowLength,
                         float* values) {
    GhostStencil st;
    std::array<double, kAxes> d0{}, width{}, h{};
    const double invHx = 1.0 / hx, invHy = 1.0 / hy;
    int longest = 0;
    for (int a = 0; a < kAxes; ++a) {
        const bool onX = a < 3;
        const int samples = onX ? gx : gy;
        const double invH = onX ? invHx : invHy;
        width[a] = onX ? g.widthX[a] : g.widthY[a - 3];
        h[a] = onX ? hx : hy;
        const double centre = onX ? g.x : g.y, r = reach(shape, width[a]);
        const long long first = ceilToInt((centre - r) * invH), last = floorToInt((centre + r) * invH);
        st.count[a] = static_cast<int>(std::clamp(last - first + 1, 0LL, floorToInt(2.0 * r * invH) + 1));
        d0[a] = static_cast<double>(first) * h[a] - centre;
        // first mod samples, without an integer division (first is within a few periods of 0).
        long long start = first - floorToInt(static_cast<double>(first) / samples) * samples;
        if (start < 0) start += samples;
        if (start >= samples) start -= samples;
        st.start[a] = static_cast<int>(start);
        longest = std::max(longest, st.count[a]);
    }
    const int n = std::min(rowLength, roundUpToLanes(longest));
    if (shape == Shape::Gaussian) {
        // exp(-d^2 / 2 s^2) at d0 + i h by the recurrence of successive ratios (three exponentials).
        std::array<double, kAxes> value{}, ratio{}, step{};
        for (int a = 0; a < kAxes; ++a) {
            const double inv = 1.0 / (2.0 * width[a] * width[a]);
            value[a] = std::exp(-d0[a] * d0[a] * inv);
            ratio[a] = std::exp(-(2.0 * d0[a] * h[a] + h[a] * h[a]) * inv);
            step[a] = std::exp(-2.0 * h[a] * h[a] * inv);
        }
        for (int i = 0; i < n; ++i)
            for (int a = 0; a < kAxes; ++a) {
                values[a * rowLength + i] = static_cast<float>(value[a]);
                value[a] *= ratio[a];
                ratio[a] *= step[a];
            }
        return st;
    }
    // cos^2(pi d / 2w) = (1 + cos(pi d / w)) / 2 by rotation, zero where |d| >= w.
    std::array<double, kAxes> c{}, sn{}, c1{}, s1{};
    for (int a = 0; a < kAxes; ++a) {
        const double k = std::numbers::pi / width[a];
        c[a] = std::cos(k * d0[a]);
        sn[a] = std::sin(k * d0[a]);
        c1[a] = std::cos(k * h[a]);
        s1[a] = std::sin(k * h[a]);
    }
    for (int i = 0; i < n; ++i)
        for (int a = 0; a < kAxes; ++a) {
            const double d = d0[a] + i * h[a];
            values[a * rowLength + i] = std::abs(d) < width[a] ? static_cast<float>(0.5 * (1.0 + c[a])) : 0.0f;
            const double nc = c[a] * c1[a] - sn[a] * s1[a];
            sn[a] = sn[a] * c1[a] + c[a] * s1[a];
            c[a] = nc;
        }
    return st;
}

// The r2c plans of the grids, made once per size and kept (FFTW's planner is slow next to these
// small transforms, and frames repeat their sizes); executed on each task's own arrays, which FFTW
// allows concurrently. Arrays from fftwf_malloc share the planning arrays' alignment. Destroyed at
// exit; the planner's mutex is made first, so it outlives the cache.
class GridTransforms {
  public:
    GridTransforms() : mutex_(fftwPlannerMutex()) {}
    ~GridTransforms() {
        for (auto& [size, plan] : plans_) fftwf_destroy_plan(plan);
    }
    GridTransforms(const GridTransforms&) = delete;
    GridTransforms& operator=(const GridTransforms&) = delete;

    fftwf_plan get(int gx, int gy) {
        std::lock_guard<std::mutex> lock(mutex_);
        fftwf_plan& plan = plans_[{gx, gy}];
        if (!plan) {
            const std::size_t cells = static_cast<std::size_t>(gx) * gy,
                              half = static_cast<std::size_t>(gx / 2 + 1) * gy;
            const auto in = fftwArray<float>(cells);
            const auto out = fftwArray<fftwf_complex>(half);
            plan = fftwf_plan_dft_r2c_2d(gy, gx, in.get(), out.get(), FFTW_ESTIMATE);
        }
        return plan;
    }

  private:
    std::mutex& mutex_;
    std::map<std::pair<int, int>, fftwf_plan> plans_;
};

} // namespace

fftwf_plan gridTransform(int gx, int gy) {
    static GridTransforms transforms;
    return transforms.get(gx, gy);
}

int gridSamples(Shape shape, int terms, double narrowest, double period, double error) {
    const double beyond = kAliasMargin * spectralCutoff(shape, error) * period / (2.0 * std::numbers::pi * narrowest);
    const double needed = std::max(2.0 * terms + 1.0, terms + std::ceil(beyond));
    return fftFriendly(static_cast<int>(std::min(needed, double(1 << 20))));
}

int stencilSamples(Shape shape, double width, double spacing) {
    return static_cast<int>(std::floor(2.0 * reach(shape, width) / spacing)) + 1;
}

// F(n, +-m) = sum s exp(-i a) exp(-+i b), a = 2 pi n i / Gx, b = 2 pi m j / Gy, so
// A = Re(F+ + F-)/2, B = Im(F- - F+)/2, C = -Im(F+ + F-)/2, D = Re(F- - F+)/2, all over Gx Gy.
std::vector<double> coefficientsOfTransform(const fftwf_complex* f, int gx, int gy, int nb, int mb) {
    const int hxOut = gx / 2 + 1;
    const double half = 0.5 / (double(gx) * gy);
    std::vector<double> z(static_cast<std::size_t>(4) * nb * mb);
    const auto at = [&](int row, int col) -> double& { return z[static_cast<std::size_t>(row) * 2 * mb + col]; };
    for (int n = 0; n < nb; ++n)
        for (int m = 0; m < mb; ++m) {
            const fftwf_complex& fp = f[static_cast<std::size_t>(m) * hxOut + n];
            const fftwf_complex& fm = f[static_cast<std::size_t>((gy - m) % gy) * hxOut + n];
            at(n, m) = half * (double(fp[0]) + fm[0]);
            at(n, mb + m) = half * (double(fm[1]) - fp[1]);
            at(nb + n, m) = -half * (double(fp[1]) + fm[1]);
            at(nb + n, mb + m) = half * (double(fm[0]) - fp[0]);
        }
    return z;
}

std::array<std::vector<double>, 3> accumulateGridded(const std::vector<Ghost>& ghosts, const AccumulationGroup& group,
                                                     std::size_t first, std::size_t count, double periodX,
                                                     double periodY) {
    const int gx = group.gridX, gy = group.gridY;
    const double hx = periodX / gx, hy = periodY / gy;
    // Padded grids: stencils run on past G (by up to a stencil and a lane group) and are folded
    // back afterwards.
    const int longX = stencilSamples(group.shape, group.widestX, hx),
              longY = stencilSamples(group.shape, group.widestY, hy);
    const int rowLength = roundUpToLanes(std::max(longX, longY));
    const std::size_t stride = static_cast<std::size_t>(gx + longX + kLanes),
                      plane = stride * static_cast<std::size_t>(gy + longY);
    std::vector<float> grid(3 * plane, 0.0f);
    std::vector<float> values(static_cast<std::size_t>(kAxes) * rowLength);
    constexpr std::size_t kAhead = 8; // ghosts are scattered over memory: fetch a few ahead
    for (std::size_t r = first; r < first + count; ++r) {
        if (r + kAhead < first + count) __builtin_prefetch(&ghosts[group.members[r + kAhead]]);
        const Ghost& g = ghosts[group.members[r]];
        const GhostStencil st = sampleGhost(group.shape, g, hx, hy, gx, gy, rowLength, values.data());
        for (int c = 0; c < 3; ++c) {
            const float* px = &values[static_cast<std::size_t>(c) * rowLength];
            const float* qy = &values[static_cast<std::size_t>(3 + c) * rowLength];
            const int sx = roundUpToLanes(st.count[c]);
            const auto alpha = static_cast<float>(g.peak(c));
            float* base = &grid[c * plane + static_cast<std::size_t>(st.start[c])];
            for (int j = 0; j < st.count[3 + c]; ++j) {
                float* row = base + static_cast<std::size_t>(st.start[3 + c] + j) * stride;
                const float q = alpha * qy[j];
                for (int i = 0; i < sx; i += kLanes)
                    for (int l = 0; l < kLanes; ++l) row[i + l] += q * px[i + l];
            }
        }
    }
    const std::size_t cells = static_cast<std::size_t>(gx) * gy;
    const int hxOut = gx / 2 + 1;
    const auto in = fftwArray<float>(cells);
    const auto out = fftwArray<fftwf_complex>(static_cast<std::size_t>(hxOut) * gy);
    if (!in || !out) throw Error(ErrorKind::Runtime, "out of memory for a gridded accumulation");
    const fftwf_plan plan = gridTransform(gx, gy);
    std::array<std::vector<double>, 3> z;
    for (int c = 0; c < 3; ++c) {
        // Fold the padding onto the period (a stencil longer than the period folds more than once).
        std::fill(in.get(), in.get() + cells, 0.0f);
        for (int j = 0; j < gy + longY; ++j) {
            float* dst = in.get() + static_cast<std::size_t>(j % gy) * gx;
            const float* src = &grid[c * plane + static_cast<std::size_t>(j) * stride];
            for (std::size_t from = 0; from < stride; from += static_cast<std::size_t>(gx)) {
                const std::size_t length = std::min(stride - from, static_cast<std::size_t>(gx));
                for (std::size_t i = 0; i < length; ++i) dst[i] += src[from + i];
            }
        }
        fftwf_execute_dft_r2c(plan, in.get(), out.get());
        z[c] = coefficientsOfTransform(out.get(), gx, gy, group.n, group.m);
    }
    return z;
}

} // namespace ff::fourier
