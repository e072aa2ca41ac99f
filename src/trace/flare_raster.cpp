#include "trace/flare_raster.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ff::trace {

namespace {

using Vec2 = glm::dvec2;

double cross(const Vec2& a, const Vec2& b, const Vec2& c) { return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x); }

// Area of the part of a convex polygon inside the axis-aligned box [x0, x1] x [y0, y1]
// (Sutherland-Hodgman against the four box edges, then the shoelace formula).
double clippedArea(const std::array<Vec2, 3>& tri, double x0, double y0, double x1, double y1) {
    std::array<Vec2, 9> a{}, b{};
    std::size_t na = 3;
    for (std::size_t i = 0; i < 3; ++i) a[i] = tri[i];
    auto clip = [&](auto inside, auto intersect) {
        std::size_t nb = 0;
        for (std::size_t i = 0; i < na; ++i) {
            const Vec2& p = a[i];
            const Vec2& q = a[(i + 1) % na];
            const bool ip = inside(p), iq = inside(q);
            if (ip) b[nb++] = p;
            if (ip != iq) b[nb++] = intersect(p, q);
        }
        a = b;
        na = nb;
    };
    clip([&](const Vec2& p) { return p.x >= x0; }, [&](const Vec2& p, const Vec2& q) { return Vec2(x0, p.y + (q.y - p.y) * (x0 - p.x) / (q.x - p.x)); });
    clip([&](const Vec2& p) { return p.x <= x1; }, [&](const Vec2& p, const Vec2& q) { return Vec2(x1, p.y + (q.y - p.y) * (x1 - p.x) / (q.x - p.x)); });
    clip([&](const Vec2& p) { return p.y >= y0; }, [&](const Vec2& p, const Vec2& q) { return Vec2(p.x + (q.x - p.x) * (y0 - p.y) / (q.y - p.y), y0); });
    clip([&](const Vec2& p) { return p.y <= y1; }, [&](const Vec2& p, const Vec2& q) { return Vec2(p.x + (q.x - p.x) * (y1 - p.y) / (q.y - p.y), y1); });
    double area = 0.0;
    for (std::size_t i = 0; i < na; ++i) area += a[i].x * a[(i + 1) % na].y - a[(i + 1) % na].x * a[i].y;
    return 0.5 * std::abs(area);
}

// The x-interval where the horizontal line at y crosses the triangle; false if it misses it.
bool span(const std::array<Vec2, 3>& t, double y, double& xl, double& xr) {
    xl = 1e300;
    xr = -1e300;
    for (int e = 0; e < 3; ++e) {
        const Vec2& a = t[e];
        const Vec2& b = t[(e + 1) % 3];
        if ((a.y - y) * (b.y - y) > 0.0 || a.y == b.y) continue;
        const double x = a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y);
        xl = std::min(xl, x);
        xr = std::max(xr, x);
    }
    return xl <= xr;
}

class Rasterizer {
public:
    Rasterizer(const ImageFrame& f, std::vector<double>& img, RasterStats& st) : frame_(f), image_(img), stats_(st) {}

    // Deposits energy e uniformly over triangle t (pixel coordinates) with exact area coverage.
    void triangle(const std::array<Vec2, 3>& t, double e) {
        const double area = 0.5 * std::abs(cross(t[0], t[1], t[2]));
        const double xMin = std::min({t[0].x, t[1].x, t[2].x}), xMax = std::max({t[0].x, t[1].x, t[2].x});
        const double yMin = std::min({t[0].y, t[1].y, t[2].y}), yMax = std::max({t[0].y, t[1].y, t[2].y});
        const int px0 = static_cast<int>(std::floor(xMin)), px1 = static_cast<int>(std::floor(xMax));
        const int py0 = static_cast<int>(std::floor(yMin)), py1 = static_cast<int>(std::floor(yMax));
        if (px0 == px1 && py0 == py1) { // inside one pixel (also catches degenerate triangles)
            deposit(px0, py0, e);
            return;
        }
        if (area <= 0.0) {
            point(0.5 * (xMin + xMax), 0.5 * (yMin + yMax), e);
            return;
        }
        const double density = e / area;
        // Edge functions, oriented so the interior is positive: a pixel whose four corners are all
        // inside is covered fully, one whose corners are all outside one edge not at all; only the
        // pixels the edges cross need clipping.
        const double orient = cross(t[0], t[1], t[2]) > 0.0 ? 1.0 : -1.0;
        auto inside = [&](int edge, double x, double y) {
            const Vec2& a = t[edge];
            const Vec2& b = t[(edge + 1) % 3];
            return orient * ((b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x));
        };
        // Pixels entirely outside the image cannot receive energy: count that part as off-image.
        double drawn = 0.0;
        const int cx0 = std::max(px0, 0), cx1 = std::min(px1, frame_.width - 1);
        const int cy0 = std::max(py0, 0), cy1 = std::min(py1, frame_.height - 1);
        for (int py = cy0; py <= cy1; ++py) {
            // A pixel is fully inside the (convex) triangle iff it lies within the triangle's x-span
            // at both its top and its bottom edge: those pixels take density x 1 without tests.
            double topL, topR, botL, botR;
            int fullFrom = 1, fullTo = 0; // empty unless both spans exist
            if (span(t, py, topL, topR) && span(t, py + 1.0, botL, botR)) {
                fullFrom = static_cast<int>(std::ceil(std::max(topL, botL)));
                fullTo = static_cast<int>(std::floor(std::min(topR, botR))) - 1;
            }
            double* row = &image_[static_cast<std::size_t>(py) * frame_.width];
            for (int px = cx0; px <= cx1; ++px) {
                if (px >= fullFrom && px <= fullTo) {
                    const int last = std::min(fullTo, cx1);
                    for (int q = px; q <= last; ++q) row[q] += density;
                    drawn += density * (last - px + 1);
                    px = last;
                    continue;
                }
                bool full = true, empty = false;
                for (int edge = 0; edge < 3 && !empty; ++edge) {
                    int in = 0;
                    for (int c = 0; c < 4; ++c) in += inside(edge, px + (c & 1), py + (c >> 1)) >= 0.0;
                    full = full && in == 4;
                    empty = in == 0;
                }
                if (empty) continue;
                const double a = full ? 1.0 : clippedArea(t, px, py, px + 1.0, py + 1.0);
                if (a <= 0.0) continue;
                row[px] += density * a;
                drawn += density * a;
            }
        }
        // Inside the frame the whole energy was drawn (up to rounding); only a triangle reaching past
        // the frame loses the part outside.
        const bool inFrame = px0 >= 0 && py0 >= 0 && px1 < frame_.width && py1 < frame_.height;
        stats_.deposited += inFrame ? e : drawn;
        if (!inFrame) stats_.offImage += std::max(0.0, e - drawn);
    }

    // Bilinear splat of energy e at pixel position (x, y).
    void point(double x, double y, double e) {
        const double fx = x - 0.5, fy = y - 0.5;
        const int ix = static_cast<int>(std::floor(fx)), iy = static_cast<int>(std::floor(fy));
        const double ax = fx - ix, ay = fy - iy;
        deposit(ix, iy, e * (1 - ax) * (1 - ay));
        deposit(ix + 1, iy, e * ax * (1 - ay));
        deposit(ix, iy + 1, e * (1 - ax) * ay);
        deposit(ix + 1, iy + 1, e * ax * ay);
    }

private:
    void deposit(int px, int py, double e) {
        if (px < 0 || py < 0 || px >= frame_.width || py >= frame_.height) {
            stats_.offImage += e;
            return;
        }
        image_[static_cast<std::size_t>(py) * frame_.width + px] += e;
        stats_.deposited += e;
    }

    const ImageFrame& frame_;
    std::vector<double>& image_;
    RasterStats& stats_;
};

} // namespace

void depositPolygon(std::span<const Vec2> poly, double e, const ImageFrame& frame, std::vector<double>& image,
                    RasterStats& stats) {
    Rasterizer r(frame, image, stats);
    if (poly.empty() || e == 0.0) return;
    // A fan from the first vertex, each triangle's share of the energy by its area.
    double total = 0.0;
    for (std::size_t i = 1; i + 1 < poly.size(); ++i) total += std::abs(cross(poly[0], poly[i], poly[i + 1]));
    if (!(total > 0.0)) {
        Vec2 mean(0.0);
        for (const Vec2& p : poly) mean += p;
        mean /= static_cast<double>(poly.size());
        r.point(mean.x, mean.y, e);
        return;
    }
    for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
        const double a = std::abs(cross(poly[0], poly[i], poly[i + 1]));
        if (a > 0.0) r.triangle({poly[0], poly[i], poly[i + 1]}, e * a / total);
    }
}

Bundle cornerBundle(const PupilFrame& frame, const Field& field, const Bundle& centres) {
    // n + 1 corner rays per side over the same square: a grid of n + 1 cells of the same size whose
    // centres sit on the corners, i.e. shifted by half a cell.
    const double half = 0.5 * centres.cell * (centres.n + 1);
    const double cx = centres.x0 + 0.5 * centres.cell * centres.n, cy = centres.y0 + 0.5 * centres.cell * centres.n;
    return gridBundle(frame, field, centres.n + 1, cx, cy, half, false);
}

namespace {

// Derivative of the landing point (pixels) along one grid axis from the neighbouring centre rays:
// central difference, else one-sided; false when neither neighbour arrives.
bool derivative(const Bundle& b, const std::vector<RayResult>& centre, const ImageFrame& frame, int i, int j, int di, int dj, Vec2& d) {
    const int n = b.n;
    auto alive = [&](int a, int c) {
        if (a < 0 || c < 0 || a >= n || c >= n) return false;
        const std::size_t k = static_cast<std::size_t>(c) * n + a;
        return b.launched[k] && centre[k].status == optics::RayStatus::Ok;
    };
    auto at = [&](int a, int c) {
        const RayResult& h = centre[static_cast<std::size_t>(c) * n + a];
        return frame.sensorToPixel(h.sensorPoint.x, h.sensorPoint.y);
    };
    const bool plus = alive(i + di, j + dj), minus = alive(i - di, j - dj);
    if (plus && minus) d = 0.5 * (at(i + di, j + dj) - at(i - di, j - dj));
    else if (plus) d = at(i + di, j + dj) - at(i, j);
    else if (minus) d = at(i, j) - at(i - di, j - dj);
    else return false;
    return true;
}

// The footprint edge vectors (pixels per cell along the grid's i and j axes) of cell (i, j), from the
// neighbouring centre rays; false when a neighbour is missing along an axis.
bool cellJacobian(const Bundle& b, const std::vector<RayResult>& centre, const ImageFrame& frame, int i, int j, Vec2& du, Vec2& dv) {
    return derivative(b, centre, frame, i, j, 1, 0, du) && derivative(b, centre, frame, i, j, 0, 1, dv);
}

} // namespace

void rasterizeCells(const Bundle& b, const std::vector<RayResult>& centre, const std::vector<RayResult>& corner,
                    double scale, const ImageFrame& frame, std::vector<double>& image, RasterStats& stats) {
    Rasterizer r(frame, image, stats);
    const int n = b.n;
    auto px = [&](const RayResult& h) { return frame.sensorToPixel(h.sensorPoint.x, h.sensorPoint.y); };
    auto alive = [&](int i, int j) {
        const std::size_t k = static_cast<std::size_t>(j) * n + i;
        return b.launched[k] && centre[k].status == optics::RayStatus::Ok;
    };
    auto at = [&](int i, int j) { return px(centre[static_cast<std::size_t>(j) * n + i]); };
    auto drawQuad = [&](const Vec2& p0, const Vec2& p1, const Vec2& p2, const Vec2& p3, double e) {
        // Split along the diagonal whose two triangles keep one orientation; false if the quad folds.
        const double a012 = cross(p0, p1, p2), a023 = cross(p0, p2, p3);
        const double a013 = cross(p0, p1, p3), a123 = cross(p1, p2, p3);
        if (a012 * a023 > 0.0) {
            const double w = std::abs(a012) / (std::abs(a012) + std::abs(a023));
            r.triangle({p0, p1, p2}, e * w);
            r.triangle({p0, p2, p3}, e * (1.0 - w));
            return true;
        }
        if (a013 * a123 > 0.0) {
            const double w = std::abs(a013) / (std::abs(a013) + std::abs(a123));
            r.triangle({p0, p1, p3}, e * w);
            r.triangle({p1, p2, p3}, e * (1.0 - w));
            return true;
        }
        return false;
    };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t k = static_cast<std::size_t>(j) * n + i;
            if (!alive(i, j)) continue; // a lost centre ray contributes nothing
            const double e = centre[k].weight * b.cellArea * scale;
            if (e <= 0.0) continue;
            const RayResult* c[4] = {&corner[static_cast<std::size_t>(j) * (n + 1) + i], &corner[static_cast<std::size_t>(j) * (n + 1) + i + 1],
                                     &corner[static_cast<std::size_t>(j + 1) * (n + 1) + i + 1], &corner[static_cast<std::size_t>(j + 1) * (n + 1) + i]};
            bool all = true;
            for (const RayResult* h : c) all = all && h->status == optics::RayStatus::Ok;
            if (all && drawQuad(px(*c[0]), px(*c[1]), px(*c[2]), px(*c[3]), e)) {
                ++stats.quads;
                continue;
            }
            // A cell at a vignetting edge, or folded by a caustic: its footprint is the parallelogram
            // the local Jacobian (from neighbouring centre rays) maps the cell to, around its centre ray.
            const Vec2 p = at(i, j);
            Vec2 du, dv;
            if (cellJacobian(b, centre, frame, i, j, du, dv) &&
                drawQuad(p - 0.5 * du - 0.5 * dv, p + 0.5 * du - 0.5 * dv, p + 0.5 * du + 0.5 * dv,
                         p - 0.5 * du + 0.5 * dv, e)) {
                ++stats.quads;
                continue;
            }
            r.point(p.x, p.y, e); // isolated cell: no neighbour tells its size
            ++stats.splats;
        }
}

} // namespace ff::trace
