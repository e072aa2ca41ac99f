#include "trace/flare_raster.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ff::trace {

namespace {

using Vec2 = glm::dvec2;

// A simple polygon clipped to the box [x0, x1] x [y0, y1] (Sutherland-Hodgman).
std::vector<Vec2> clippedToBox(std::span<const Vec2> poly, double x0, double y0, double x1, double y1) {
    std::vector<Vec2> a(poly.begin(), poly.end()), b;
    auto clip = [&](auto inside, auto intersect) {
        b.clear();
        for (std::size_t i = 0; i < a.size(); ++i) {
            const Vec2& p = a[i];
            const Vec2& q = a[(i + 1) % a.size()];
            const bool ip = inside(p), iq = inside(q);
            if (ip) b.push_back(p);
            if (ip != iq) b.push_back(intersect(p, q));
        }
        std::swap(a, b);
    };
    clip([&](const Vec2& p) { return p.x >= x0; },
         [&](const Vec2& p, const Vec2& q) { return Vec2(x0, p.y + (q.y - p.y) * (x0 - p.x) / (q.x - p.x)); });
    clip([&](const Vec2& p) { return p.x <= x1; },
         [&](const Vec2& p, const Vec2& q) { return Vec2(x1, p.y + (q.y - p.y) * (x1 - p.x) / (q.x - p.x)); });
    clip([&](const Vec2& p) { return p.y >= y0; },
         [&](const Vec2& p, const Vec2& q) { return Vec2(p.x + (q.x - p.x) * (y0 - p.y) / (q.y - p.y), y0); });
    clip([&](const Vec2& p) { return p.y <= y1; },
         [&](const Vec2& p, const Vec2& q) { return Vec2(p.x + (q.x - p.x) * (y1 - p.y) / (q.y - p.y), y1); });
    return a;
}

// Signed area (positive when clockwise on the screen, +y down) and first moments (integrals of x and
// y) of a polygon: Green's theorem over its edges.
struct Moments {
    double area = 0.0, mx = 0.0, my = 0.0;
};
Moments momentsOf(std::span<const Vec2> p) {
    Moments m;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec2 &a = p[i], &b = p[(i + 1) % p.size()];
        const double cross = a.x * b.y - b.x * a.y;
        m.area += cross;
        m.mx += (a.x + b.x) * cross;
        m.my += (a.y + b.y) * cross;
    }
    m.area *= 0.5;
    m.mx /= 6.0;
    m.my /= 6.0;
    return m;
}

} // namespace

CoverageRaster::CoverageRaster(const ImageFrame& frame)
    : frame_(frame), stride_(static_cast<std::size_t>(frame.width) + 2),
      acc_(stride_ * static_cast<std::size_t>(std::max(frame.height, 0)), 0.0) {}

void CoverageRaster::polygon(std::span<const Vec2> poly, double e, RasterStats& stats) {
    polygon(poly, e, Vec2(0.0), stats);
}

void CoverageRaster::polygon(std::span<const Vec2> poly, double e, const Vec2& g, RasterStats& stats) {
    if (poly.empty() || e == 0.0) return;
    const Moments m = momentsOf(poly);
    const double area = m.area;
    Vec2 lo(1e300), hi(-1e300);
    for (const Vec2& p : poly) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
    if (!std::isfinite(area) || !std::isfinite(m.mx) || !std::isfinite(m.my)) { // a vertex at infinity or NaN
        stats.offImage += e;
        return;
    }
    // A polygon inside one pixel puts its energy in that pixel; one of no area (a point, a segment) is
    // splatted bilinearly at its vertices' mean.
    const bool nearFrame = std::abs(lo.x) < 1e9 && std::abs(lo.y) < 1e9; // pixel indices fit an int
    if (nearFrame && std::floor(lo.x) == std::floor(hi.x) && std::floor(lo.y) == std::floor(hi.y) && area != 0.0) {
        pixel(static_cast<int>(std::floor(lo.x)), static_cast<int>(std::floor(lo.y)), e, stats);
        return;
    }
    if (area == 0.0) {
        Vec2 mean(0.0);
        for (const Vec2& p : poly) mean += p;
        point(mean / static_cast<double>(poly.size()), e, stats);
        return;
    }
    // The density (e / |A|) (1 + g . (p - c)) as d0 + dx x + dy y. An edge running down (+y) adds
    // the density to the right of it: a polygon of positive signed area (clockwise on the screen) has
    // its downward edges on the left, hence the sign -1 / A.
    const Vec2 c(m.mx / area, m.my / area);
    const double s = -e / area;
    const Density d{s * (1.0 - g.x * c.x - g.y * c.y), s * g.x, s * g.y};
    const bool linear = g.x != 0.0 || g.y != 0.0;
    if (linear && lanes_ == 1) {
        // Interleave a slope beside every entry: a linear segment writes both in one cache line.
        std::vector<double> both(2 * acc_.size(), 0.0);
        for (std::size_t k = 0; k < acc_.size(); ++k) both[2 * k] = acc_[k];
        acc_ = std::move(both);
        lanes_ = 2;
    }
    for (std::size_t i = 0; i < poly.size(); ++i) edge(poly[i], poly[(i + 1) % poly.size()], linear ? d : Density{s});
    const bool inFrame = lo.x >= 0.0 && lo.y >= 0.0 && hi.x <= frame_.width && hi.y <= frame_.height;
    double drawn = e;
    if (!inFrame) {
        const std::vector<Vec2> in = clippedToBox(poly, 0.0, 0.0, frame_.width, frame_.height);
        const Moments mi = momentsOf(in);
        drawn = e / area * (mi.area + g.x * (mi.mx - c.x * mi.area) + g.y * (mi.my - c.y * mi.area));
    }
    stats.deposited += drawn;
    stats.offImage += std::max(0.0, e - drawn);
}

void CoverageRaster::pixel(int px, int py, double e, RasterStats& stats) {
    if (px < 0 || py < 0 || px >= frame_.width || py >= frame_.height) {
        stats.offImage += e;
        return;
    }
    double* row = &acc_[static_cast<std::size_t>(py) * stride_ * lanes_];
    row[px * lanes_] += e; // the prefix sum carries it to px only
    row[(px + 1) * lanes_] -= e;
    stats.deposited += e;
}

void CoverageRaster::point(const Vec2& p, double e, RasterStats& stats) {
    const double fx = p.x - 0.5, fy = p.y - 0.5;
    const double ix = std::floor(fx), iy = std::floor(fy);
    if (!(std::abs(ix) < 1e9 && std::abs(iy) < 1e9)) {
        stats.offImage += e;
        return;
    }
    const double ax = fx - ix, ay = fy - iy;
    const int x = static_cast<int>(ix), y = static_cast<int>(iy);
    pixel(x, y, e * (1 - ax) * (1 - ay), stats);
    pixel(x + 1, y, e * ax * (1 - ay), stats);
    pixel(x, y + 1, e * (1 - ax) * ay, stats);
    pixel(x + 1, y + 1, e * ax * ay, stats);
}

void CoverageRaster::edge(Vec2 a, Vec2 b, const Density& density) {
    if (a.y == b.y) return;
    Density d = density;
    if (a.y > b.y) {
        std::swap(a, b);
        d = {-d.d0, -d.dx, -d.dy};
    }
    const bool linear = d.dx != 0.0 || d.dy != 0.0;
    // Rows outside the frame receive nothing.
    const double H = frame_.height, W = frame_.width;
    const double y0 = std::max(a.y, 0.0), y1 = std::min(b.y, H);
    if (!(y0 < y1)) return;
    const double dxdy = (b.x - a.x) / (b.y - a.y);
    const Vec2 p(a.x + (y0 - a.y) * dxdy, y0), q(a.x + (y1 - a.y) * dxdy, y1);
    // Columns: the part right of the frame adds only beyond it and is dropped; the part left of it is
    // moved onto x = 0, which adds the same to every pixel of the frame (whole columns receive the
    // same from a segment anywhere to their left, uniform density or linear).
    double tA = 2.0, tB = 2.0; // the parameters where the segment crosses x = 0 and x = W, if it does
    if (p.x * q.x < 0.0) tA = -p.x / (q.x - p.x);
    if ((p.x - W) * (q.x - W) < 0.0) tB = (W - p.x) / (q.x - p.x);
    if (tB < tA) std::swap(tA, tB);
    const double cuts[4] = {0.0, std::min(tA, 1.0), std::min(tB, 1.0), 1.0};
    for (int k = 0; k < 3; ++k) {
        const double t0 = cuts[k], t1 = cuts[k + 1];
        if (!(t1 > t0)) continue;
        Vec2 s = p + t0 * (q - p), t = p + t1 * (q - p);
        const double xm = 0.5 * (s.x + t.x);
        if (xm >= W) continue;
        if (xm <= 0.0) s.x = t.x = 0.0;
        s.x = std::clamp(s.x, 0.0, W);
        t.x = std::clamp(t.x, 0.0, W);
        if (linear)
            linearSegment(s, t, d);
        else
            segment(s, t, d.d0);
    }
}

void CoverageRaster::segment(const Vec2& p0, const Vec2& p1, double d) {
    // p0.y < p1.y, both inside [0, W] x [0, H]. In each row the segment crosses, the area to its right
    // (times d) is split over the columns it spans: column c gets the area right of the segment within
    // [c, c + 1], as the difference of what reaches c and what reaches c + 1, so the row's prefix sum
    // gives every pixel exactly its covered area.
    const double dxdy = (p1.x - p0.x) / (p1.y - p0.y);
    double x = p0.x;
    const int rowFrom = static_cast<int>(std::floor(p0.y)), rowTo = static_cast<int>(std::ceil(p1.y));
    for (int y = rowFrom; y < std::min(rowTo, frame_.height); ++y) {
        const double dy = std::min(y + 1.0, p1.y) - std::max(static_cast<double>(y), p0.y);
        const double xNext = y + 1.0 >= p1.y ? p1.x : x + dxdy * dy;
        const double h = dy * d;
        double* row = &acc_[static_cast<std::size_t>(y) * stride_ * lanes_];
        const std::size_t L = lanes_;
        const double x0 = std::min(x, xNext), x1 = std::max(x, xNext);
        const double x0Floor = std::floor(x0), x1Ceil = std::ceil(x1);
        const int i0 = static_cast<int>(x0Floor), i1 = static_cast<int>(x1Ceil);
        if (i1 <= i0 + 1) {
            // Within one column: the trapezoid right of the segment covers 1 - (mean x - column).
            const double f = 0.5 * (x + xNext) - x0Floor;
            row[i0 * L] += h * (1.0 - f);
            row[(i0 + 1) * L] += h * f;
        } else {
            // Across columns: the fraction of the row's height left of column line X is
            // (X - x0) / (x1 - x0), integrated over each column.
            const double s = 1.0 / (x1 - x0);
            const double f0 = x0 - x0Floor;
            const double a0 = 0.5 * s * (1.0 - f0) * (1.0 - f0); // first column
            const double f1 = x1 - x1Ceil + 1.0;
            const double am = 0.5 * s * f1 * f1; // beyond the last column's left part
            row[i0 * L] += h * a0;
            if (i1 == i0 + 2) {
                row[(i0 + 1) * L] += h * (1.0 - a0 - am);
            } else {
                const double a1 = s * (1.5 - f0);
                row[(i0 + 1) * L] += h * (a1 - a0);
                for (int i = i0 + 2; i < i1 - 1; ++i) row[i * L] += h * s;
                const double a2 = a1 + (i1 - i0 - 3) * s;
                row[(i1 - 1) * L] += h * (1.0 - a2 - am);
            }
            row[i1 * L] += h * am;
        }
        x = xNext;
    }
}

void CoverageRaster::linearSegment(const Vec2& p0, const Vec2& p1, const Density& d) {
    // p0.y < p1.y, both inside [0, W] x [0, H]. In each row the segment crosses, between ya and yb,
    // column j receives the integral of the density over the part of [j, j + 1] x [ya, yb] right of
    // the segment: its exact value in the columns the segment spans (the entries), and
    // (yb - ya) (d0 + dy ymean + dx (j + 1/2)) in those wholly right of it, from column i1 on: that
    // value at i1 through the entries, and the slope (yb - ya) dx beside them, which the release sums
    // twice (the slope's sum times the distance from i1). Only additions: exact as integers too.
    const double dxdy = (p1.x - p0.x) / (p1.y - p0.y);
    double x = p0.x;
    const int rowFrom = static_cast<int>(std::floor(p0.y)), rowTo = static_cast<int>(std::ceil(p1.y));
    for (int y = rowFrom; y < std::min(rowTo, frame_.height); ++y) {
        const double ya = std::max(static_cast<double>(y), p0.y), yb = std::min(y + 1.0, p1.y);
        const double h = yb - ya;
        const double xNext = y + 1.0 >= p1.y ? p1.x : x + dxdy * h;
        double* row = &acc_[static_cast<std::size_t>(y) * stride_ * 2]; // lanes_ == 2: entry, slope
        const int i0 = static_cast<int>(std::floor(std::min(x, xNext))),
                  i1 = static_cast<int>(std::ceil(std::max(x, xNext)));
        // Column j's value is P(j + 1) - P(j), P(c) the integral of the density over the row's part
        // right of the segment and left of the line x = c. In coordinates from (i0, ya), with
        // tau = y - ya, the segment at xl + s tau and the density e0 + dx X + dy tau:
        //   P(c) = Int_{x(tau) < c} [Phi(c, tau) - Phi(x(tau), tau)] dtau,  Phi(X, tau) = (e0 + dy tau) X + dx X^2 / 2,
        // Phi(x(tau), tau) = q0 + q1 tau + q2 tau^2 with the antiderivative R below, and
        // {tau : x(tau) < c} an interval of [0, h] ending where the segment crosses c.
        const double s = h > 0.0 ? (xNext - x) / h : 0.0, xl = x - i0;
        const double e0 = d.d0 + d.dx * i0 + d.dy * ya;
        const double q0 = e0 * xl + 0.5 * d.dx * xl * xl, q1 = e0 * s + d.dy * xl + d.dx * xl * s,
                     q2 = d.dy * s + 0.5 * d.dx * s * s;
        const double r1 = 0.5 * q1, r2 = q2 / 3.0;
        auto R = [&](double t) { return t * (q0 + t * (r1 + t * r2)); };
        double before = 0.0;
        if (i1 == i0 + 1) {
            // Within one column: P(1) over the whole of [0, h].
            before = (e0 + 0.5 * d.dx) * h + 0.5 * d.dy * h * h - R(h);
            row[2 * i0] += before;
        } else {
            const double inv = s != 0.0 ? 1.0 / s : 0.0;
            auto P = [&](double c) {
                double a = 0.0, b = h;
                if (s > 0.0)
                    b = std::clamp((c - xl) * inv, 0.0, h);
                else if (s < 0.0)
                    a = std::clamp((c - xl) * inv, 0.0, h);
                else if (!(xl < c))
                    return 0.0;
                return (e0 * c + 0.5 * d.dx * c * c) * (b - a) + 0.5 * d.dy * c * (b * b - a * a) - (R(b) - R(a));
            };
            double below = 0.0;
            for (int j = i0; j < i1; ++j) {
                const double next = P(j + 1.0 - i0), v = next - below;
                row[2 * j] += v - before;
                before = v;
                below = next;
            }
        }
        row[2 * i1] += h * (d.d0 + d.dy * 0.5 * (ya + yb) + d.dx * (i1 + 0.5)) - before;
        row[2 * i1 + 1] += h * d.dx;
        x = xNext;
    }
}

void CoverageRaster::addTo(std::vector<double>& image) const {
    const std::size_t W = static_cast<std::size_t>(std::max(frame_.width, 0));
    for (std::size_t y = 0; y < acc_.size() / (stride_ * lanes_); ++y) {
        double sum = 0.0, slope = 0.0, ramp = 0.0;
        const double* row = &acc_[y * stride_ * lanes_];
        double* out = &image[y * W];
        if (lanes_ == 1)
            for (std::size_t x = 0; x < W; ++x) {
                sum += row[x];
                out[x] += std::max(sum, 0.0);
            }
        else
            for (std::size_t x = 0; x < W; ++x) {
                sum += row[2 * x];
                ramp += slope, slope += row[2 * x + 1];
                out[x] += std::max(sum + ramp, 0.0);
            }
    }
}

std::vector<double> CoverageRaster::release() && {
    // The rows' prefix sums in place, then the rows packed to the frame's width (each moves left).
    const std::size_t W = static_cast<std::size_t>(std::max(frame_.width, 0));
    // Reads stay at or ahead of writes: (y stride + x) lanes >= y W + x.
    const std::size_t rows = acc_.size() / (stride_ * lanes_);
    for (std::size_t y = 0; y < rows; ++y) {
        double sum = 0.0, slope = 0.0, ramp = 0.0;
        for (std::size_t x = 0; x < W; ++x) {
            const std::size_t k = (y * stride_ + x) * lanes_;
            sum += acc_[k];
            if (lanes_ == 2) ramp += slope, slope += acc_[k + 1];
            acc_[y * W + x] = std::max(sum + ramp, 0.0);
        }
    }
    acc_.resize(W * rows);
    return std::move(acc_);
}

} // namespace ff::trace
