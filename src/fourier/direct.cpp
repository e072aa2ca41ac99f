#include "fourier/direct.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ff::fourier {

double profileIntegral(Shape s, double w, double a, double b) {
    if (s == Shape::Gaussian) {
        const double k = 1.0 / (std::numbers::sqrt2 * w);
        return w * std::sqrt(0.5 * std::numbers::pi) * (std::erf(b * k) - std::erf(a * k));
    }
    // Int cos^2(pi u / 2w) du = u/2 + (w / 2 pi) sin(pi u / w), on the support |u| < w.
    auto F = [w](double u) {
        u = std::clamp(u, -w, w);
        return 0.5 * u + w / (2.0 * std::numbers::pi) * std::sin(std::numbers::pi * u / w);
    };
    return F(b) - F(a);
}

namespace {

// One ghost's per-pixel integrals along one axis, channel by channel, over pixels [first, first + size).
struct AxisProfile {
    int first = 0, size = 0;
    std::array<std::vector<double>, 3> value;
};

AxisProfile axisProfile(Shape s, double centre, const std::array<double, 3>& widths, double extent, int pixels) {
    AxisProfile p;
    const int lo = std::max(0, static_cast<int>(std::floor(centre - extent)));
    const int hi = std::min(pixels - 1, static_cast<int>(std::floor(centre + extent)));
    if (hi < lo) return p;
    p.first = lo;
    p.size = hi - lo + 1;
    for (int c = 0; c < 3; ++c) {
        p.value[c].resize(static_cast<std::size_t>(p.size));
        for (int i = 0; i < p.size; ++i)
            p.value[c][i] = profileIntegral(s, widths[c], lo + i - centre, lo + i + 1 - centre);
    }
    return p;
}

} // namespace

void drawDirect(const std::vector<Ghost>& ghosts, FlareImage& image) {
    std::vector<std::size_t> all(ghosts.size());
    for (std::size_t k = 0; k < all.size(); ++k) all[k] = k;
    drawDirect(ghosts, all, image);
}

void drawDirect(const std::vector<Ghost>& ghosts, const std::vector<std::size_t>& which, FlareImage& image) {
    std::vector<AxisProfile> px(which.size()), py(which.size());
    std::vector<std::array<double, 3>> peak(which.size());
    tbb::parallel_for(std::size_t(0), which.size(), [&](std::size_t i) {
        const Ghost& g = ghosts[which[i]];
        px[i] = axisProfile(g.shape, g.x, g.widthX, g.extentX(), image.width);
        py[i] = axisProfile(g.shape, g.y, g.widthY, g.extentY(), image.height);
        for (int c = 0; c < 3; ++c) peak[i][c] = g.peak(c);
    });
    // Rows in parallel; within a row, ghosts in their given order: the sums do not depend on threads.
    tbb::parallel_for(0, image.height, [&](int row) {
        std::vector<double> acc(static_cast<std::size_t>(image.width));
        for (int c = 0; c < 3; ++c) {
            bool any = false;
            std::fill(acc.begin(), acc.end(), 0.0);
            for (std::size_t i = 0; i < which.size(); ++i) {
                if (px[i].size == 0 || row < py[i].first || row >= py[i].first + py[i].size) continue;
                const double f = peak[i][c] * py[i].value[c][static_cast<std::size_t>(row - py[i].first)];
                if (f == 0.0) continue;
                any = true;
                for (int k = 0; k < px[i].size; ++k)
                    acc[static_cast<std::size_t>(px[i].first + k)] += f * px[i].value[c][k];
            }
            if (!any) continue;
            float* out = &image.channel[c][static_cast<std::size_t>(row) * image.width];
            for (int x = 0; x < image.width; ++x) out[x] += static_cast<float>(acc[x]);
        }
    });
}

} // namespace ff::fourier
