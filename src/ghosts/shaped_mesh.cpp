// A ghost's mesh at one wavelength, placed in the frame (mesh_vertices.h) and cut into the clipped
// polygons it is drawn as (shaped_mesh.h).

#include "ghosts/shaped_mesh.h"

#include "ghosts/mesh_clip.h"
#include "ghosts/mesh_vertices.h"
#include "ghosts/shaped_ghosts.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace ff::ghosts {

namespace {

// Below this area (pixels^2) an element is drawn uniform: the pixel that holds it integrates its
// density's slope away (to second order), and a ghost focused to a few pixels has Jacobians too
// noisy (its landing points are 32-bit floats) for a slope to mean anything.
constexpr double kLinearMinAreaPx = 1.0;
// The irradiance never splits a cell into sub-cells narrower than this (pixels): below it, the
// sub-cells' flux lands in the pixel that holds them whatever their density.
constexpr double kIrradianceSubcellPx = 0.25;

// The irradiance (weight per pixel^2) over one cell of the grid, for the subdivision in pixels: at its
// four corners (00, 10, 01, 11) and its centre, and its map's Jacobian signs there.
struct CellIrradiance {
    std::array<double, 4> corner{};
    double centre = 0.0;
    bool fold = false; ///< the map folds over the cell (its Jacobian changes sign), or one is missing
    double areaPx = 0.0, sizePx = 0.0;
};

// The sub-cells per side k (1..maxK) that the cell's irradiance asks for, so that the error its
// elements leave in a pixel is at most `tolerance` (weight per pixel^2; docs/ghost-table.md,
// "Subdivision in pixels"). A sub-cell of size h = sizePx / k:
//   linear elements (area >= kLinearMinAreaPx): the plane's error, second order: dev / k^2, dev the
//     bicubic irradiance at the centre against the planes through the corners;
//   uniform ones: the step between neighbours, spread / k, which a pixel sees whole when h >= 1 px
//     and over a share h of it below: spread / (2k) min(1, h).
// A fold cell (the irradiance unbounded over it, its elements uniform) counts as the uniform case
// with the spread from 0 to its largest finite value. No cell is split into sub-cells narrower than
// kIrradianceSubcellPx.
int irradianceSplit(const CellIrradiance& c, double tolerance, bool linear, int maxK) {
    const int cap = std::clamp(static_cast<int>(std::ceil(c.sizePx / kIrradianceSubcellPx)), 1, maxK);
    const auto& r = c.corner;
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (double v : {r[0], r[1], r[2], r[3], c.centre})
        if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    const double spread = c.fold ? hi : std::max(0.0, hi - lo);
    const double dev = std::max(std::abs(c.centre - 0.5 * (r[0] + r[3])), std::abs(c.centre - 0.5 * (r[1] + r[2])));
    for (int k = 1; k < cap; ++k) {
        const double h = c.sizePx / k;
        const bool slope = linear && !c.fold && c.areaPx >= 2.0 * kLinearMinAreaPx * k * k;
        const double err = slope ? dev / (double(k) * k) : 0.5 * spread / k * std::min(1.0, h);
        if (err <= tolerance) return k;
    }
    return cap;
}

// The area (pixels^2) of a cell whose corners 00, 10, 01, 11 land at c00 .. c11: half the cross
// product of its diagonals.
double cellAreaPx(const double* c00, const double* c10, const double* c01, const double* c11) {
    return 0.5 * std::abs((c11[0] - c00[0]) * (c01[1] - c10[1]) - (c01[0] - c10[0]) * (c11[1] - c00[1]));
}

// The instance's brightest pixel, estimated (weight per pixel^2): the largest mean irradiance of a
// cell the apertures leave whole, over at least a pixel (a smaller cell's flux lands in about one);
// of any cell where none is whole.
double brightestPixel(const MeshVertices& m) {
    double whole = 0.0, any = 0.0;
    for (int j = 0; j < m.n; ++j)
        for (int i = 0; i < m.n; ++i) {
            const std::size_t v00 = m.index(i, j), v10 = v00 + 1, v01 = m.index(i, j + 1), v11 = v01 + 1;
            if (!(m.ok[v00] && m.ok[v10] && m.ok[v01] && m.ok[v11])) continue;
            const double *a = m.at(v00), *b = m.at(v10), *d = m.at(v01), *e = m.at(v11);
            const double areaPx = cellAreaPx(a, b, d, e);
            const double mean = 0.25 * (a[2] + b[2] + d[2] + e[2]) / std::max(areaPx, 1.0);
            if (!std::isfinite(mean)) continue;
            bool inside = true;
            for (std::size_t k = 0; k < m.C && inside; ++k)
                inside = a[3 + k] >= 0.0 && b[3 + k] >= 0.0 && d[3 + k] >= 0.0 && e[3 + k] >= 0.0;
            any = std::max(any, mean);
            if (inside) whole = std::max(whole, mean);
        }
    return whole > 0.0 ? whole : any;
}

// Cuts the cells of a mesh into sub-cells and their triangles into clipped polygons. Cells are split
// into k x k sub-cells placed by bicubic (Catmull-Rom) interpolation of the grid, k the larger of two
// rules: the bicubic surface, and the aperture edges crossing the cell, within in.flatnessPx of the
// sub-cells' flat triangles (the deviation falls as 1 / k^2), and irradianceSplit's. Cells next to the
// grid's border or a lost ray are interpolated bilinearly; those an edge crosses are cut until a
// sub-cell spans about settings.subcellPx pixels.
class CellCutter {
  public:
    CellCutter(const MeshVertices& m, const MeshInstance& in, const ShapedRenderSettings& settings,
               const trace::ImageFrame& frame, double flux, ShapedPolygons& out)
        : m_(m), in_(in), settings_(settings), frame_(frame), flux_(flux), out_(out),
          tolerance_(std::isfinite(in.irradianceError) ? in.irradianceError * brightestPixel(m) : 0.0),
          kEdge_(std::clamp(
              static_cast<int>(std::ceil(std::max(m.xMax - m.xMin, m.yMax - m.yMin) / m.n / settings.subcellPx)), 1,
              settings.maxSubdivision)),
          weights_(settings.maxSubdivision + 1), slopes_(settings.maxSubdivision + 1) {}

    void cell(int i, int j) {
        const MeshVertices& m = m_;
        const std::size_t v00 = m.index(i, j), v10 = v00 + 1, v01 = m.index(i, j + 1), v11 = v01 + 1;
        const bool all = m.ok[v00] && m.ok[v10] && m.ok[v01] && m.ok[v11];
        // The 4 x 4 neighbourhood; bilinear where it leaves the grid or meets a lost ray.
        bool cubic = all;
        for (int q = -1; q <= 2 && cubic; ++q)
            for (int r = -1; r <= 2 && cubic; ++r) {
                const int x = i + r, y = j + q;
                if (x < 0 || y < 0 || x > m.n || y > m.n || !m.ok[m.index(x, y)])
                    cubic = false;
                else
                    nb_[(q + 1) * 4 + (r + 1)] = m.at(m.index(x, y));
            }
        const std::array<const double*, 4> c{m.at(v00), m.at(v10), m.at(v01), m.at(v11)};
        // A cell with its four corners outside one aperture is dark (the margins are smooth at the
        // grid's scale; a curved edge bulging into it from outside would carry a sliver).
        for (std::size_t k = 0; k < m.C && all; ++k)
            if (c[0][3 + k] < 0.0 && c[1][3 + k] < 0.0 && c[2][3 + k] < 0.0 && c[3][3 + k] < 0.0) return;
        const int K = all ? subdivision(c, cubic) : 1;
        if (K == 1) {
            const std::array<std::size_t, 4> corners{v00, v10, v01, v11};
            for (const auto& tri : cellTriangles(m.ok[v00], m.ok[v10], m.ok[v01], m.ok[v11]))
                if (tri[0] < 4) triangle(m.at(corners[tri[0]]), m.at(corners[tri[1]]), m.at(corners[tri[2]]), 0.5);
            return;
        }
        subdivide(c, cubic, K);
    }

  private:
    // Sub-cells per side for a cell whose four corners land (c: 00, 10, 01, 11).
    int subdivision(const std::array<const double*, 4>& c, bool cubic) {
        const std::size_t C = m_.C, J = m_.J;
        // A cell that lies a cell's size beyond the frame (its bicubic surface cannot bulge further)
        // stays flat: its light only counts as leaving the frame.
        const double cx0 = std::min({c[0][0], c[1][0], c[2][0], c[3][0]}),
                     cx1 = std::max({c[0][0], c[1][0], c[2][0], c[3][0]}),
                     cy0 = std::min({c[0][1], c[1][1], c[2][1], c[3][1]}),
                     cy1 = std::max({c[0][1], c[1][1], c[2][1], c[3][1]});
        const double reach = 1.0 + std::max(cx1 - cx0, cy1 - cy0);
        if (cx1 < -reach || cy1 < -reach || cx0 > frame_.width + reach || cy0 > frame_.height + reach) return 1;
        // Deviation of the bicubic surface from the flat cell at its centre, in pixels: of the
        // landing point, and of where a cutting aperture's edge (a constraint's zero) crosses the
        // cell (the constraint's deviation over its gradient across the cell).
        auto deviation = [&](std::size_t z) {
            const double flat = 0.25 * (c[0][z] + c[1][z] + c[2][z] + c[3][z]);
            return std::abs(bicubic(half_, half_, z) - flat);
        };
        bool edge = false;
        const double landing = cubic ? std::max(deviation(0), deviation(1)) : 0.0;
        double edgeDev = 0.0;
        const double sizePx = std::max({std::abs(c[3][0] - c[0][0]), std::abs(c[1][0] - c[2][0]),
                                        std::abs(c[3][1] - c[0][1]), std::abs(c[1][1] - c[2][1])});
        for (std::size_t k = 0; k < C; ++k) {
            const double lo = std::min({c[0][3 + k], c[1][3 + k], c[2][3 + k], c[3][3 + k]}),
                         hi = std::max({c[0][3 + k], c[1][3 + k], c[2][3 + k], c[3][3 + k]});
            if (!(lo < 0.0 && hi >= 0.0)) continue;
            edge = true;
            if (cubic) edgeDev = std::max(edgeDev, deviation(3 + k) * sizePx / (hi - lo));
        }
        if (edge && !cubic) return kEdge_;
        const double edgeFlatness = in_.edgeFlatnessPx > 0.0 ? in_.edgeFlatnessPx : in_.flatnessPx;
        int K = std::clamp(
            static_cast<int>(std::ceil(std::sqrt(std::max(landing / in_.flatnessPx, edgeDev / edgeFlatness)))), 1,
            settings_.maxSubdivision);
        // Then the error the elements' density leaves in the pixels (irradianceSplit): the irradiance
        // at the corners (their Jacobians) and at the centre (the bicubic's own).
        if (cubic && sizePx > 0.0 && tolerance_ > 0.0 && std::isfinite(tolerance_)) {
            CellIrradiance ci;
            ci.sizePx = sizePx;
            ci.areaPx = cellAreaPx(c[0], c[1], c[2], c[3]);
            const double jc = bicubic(halfSlope_, half_, 0) * bicubic(half_, halfSlope_, 1) -
                              bicubic(half_, halfSlope_, 0) * bicubic(halfSlope_, half_, 1);
            ci.centre = std::max(0.0, bicubic(half_, half_, 2)) / std::abs(jc);
            bool positive = jc > 0.0, negative = jc < 0.0;
            for (int q = 0; q < 4; ++q) {
                ci.corner[q] = std::max(0.0, c[q][2]) / std::abs(c[q][J]);
                positive = positive && c[q][J] > 0.0;
                negative = negative && c[q][J] < 0.0;
            }
            ci.fold = !(positive || negative);
            K = std::max(K, irradianceSplit(ci, tolerance_, settings_.linearDensity, settings_.maxSubdivision));
        }
        return K;
    }

    // The cell as K x K sub-cells, two triangles each.
    void subdivide(const std::array<const double*, 4>& c, bool cubic, int K) {
        const std::size_t J = m_.J, S = m_.S;
        const auto& cr = weightsFor(K);
        sub_.resize(static_cast<std::size_t>(K + 1) * (K + 1) * S);
        for (int b = 0; b <= K; ++b)
            for (int a = 0; a <= K; ++a) {
                double* o = &sub_[(static_cast<std::size_t>(b) * (K + 1) + a) * S];
                // The Jacobian is the interpolating surface's own, so that each sub-triangle's
                // density agrees with its flux to second order in its size.
                if (cubic) {
                    for (std::size_t z = 0; z < J; ++z) o[z] = bicubic(cr[a], cr[b], z);
                    const auto &su = slopes_[K][a], &sv = slopes_[K][b];
                    o[J] =
                        bicubic(su, cr[b], 0) * bicubic(cr[a], sv, 1) - bicubic(cr[a], sv, 0) * bicubic(su, cr[b], 1);
                } else {
                    const double u = double(a) / K, v = double(b) / K;
                    for (std::size_t z = 0; z < J; ++z)
                        o[z] = (1 - v) * ((1 - u) * c[0][z] + u * c[1][z]) + v * ((1 - u) * c[2][z] + u * c[3][z]);
                    auto du = [&](std::size_t z) { return (1 - v) * (c[1][z] - c[0][z]) + v * (c[3][z] - c[2][z]); };
                    auto dv = [&](std::size_t z) { return (1 - u) * (c[2][z] - c[0][z]) + u * (c[3][z] - c[1][z]); };
                    o[J] = du(0) * dv(1) - dv(0) * du(1);
                }
            }
        const double subArea = 0.5 / (double(K) * K);
        for (int b = 0; b < K; ++b)
            for (int a = 0; a < K; ++a) {
                const double* s00 = &sub_[(static_cast<std::size_t>(b) * (K + 1) + a) * S];
                const double* s10 = s00 + S;
                const double* s01 = s00 + (K + 1) * S;
                const double* s11 = s01 + S;
                triangle(s00, s10, s11, subArea);
                triangle(s00, s11, s01, subArea);
            }
    }

    // A triangle's density: the plane through its vertices' irradiances (weight / |Jacobian|) where
    // the map keeps its orientation over it, as a gradient relative to the plane's value at `at` (the
    // centroid of what is drawn); 0 (uniform) where it folds, a Jacobian is missing, or it covers less
    // than kLinearMinAreaPx.
    glm::dvec2 gradientOf(const double* P, const double* Q, const double* R, const glm::dvec2& at) const {
        if (!settings_.linearDensity) return glm::dvec2(0.0);
        const std::size_t J = m_.J;
        const double jP = P[J], jQ = Q[J], jR = R[J];
        if (!(jP * jQ > 0.0 && jP * jR > 0.0)) return glm::dvec2(0.0);
        const double rP = std::max(0.0, P[2]) / std::abs(jP), rQ = std::max(0.0, Q[2]) / std::abs(jQ),
                     rR = std::max(0.0, R[2]) / std::abs(jR);
        const glm::dvec2 e1(Q[0] - P[0], Q[1] - P[1]), e2(R[0] - P[0], R[1] - P[1]);
        const double det = e1.x * e2.y - e1.y * e2.x;
        if (!(std::abs(det) >= 2.0 * kLinearMinAreaPx)) return glm::dvec2(0.0);
        const glm::dvec2 grad(((rQ - rP) * e2.y - (rR - rP) * e1.y) / det, ((rR - rP) * e1.x - (rQ - rP) * e2.x) / det);
        const double value = rP + grad.x * (at.x - P[0]) + grad.y * (at.y - P[1]);
        if (!(value > 0.0) || !std::isfinite(grad.x) || !std::isfinite(grad.y)) return glm::dvec2(0.0);
        return grad / value;
    }

    static glm::dvec2 centroid(const glm::dvec2* p, std::size_t count) {
        double a = 0.0;
        glm::dvec2 sum(0.0);
        for (std::size_t k = 0; k < count; ++k) {
            const glm::dvec2 &u = p[k], &v = p[(k + 1) % count];
            const double cross = u.x * v.y - v.x * u.y;
            a += cross;
            sum += (u + v) * cross;
        }
        return a != 0.0 ? sum / (3.0 * a) : p[0];
    }

    // The triangle of vertices P, Q, R (pupil area `area` cells), clipped by the constraints that
    // change sign over it, added to out_ with its weight's flux.
    void triangle(const double* P, const double* Q, const double* R, double area) {
        const double e = flux_ * area * (P[2] + Q[2] + R[2]) / 3.0;
        if (!(e > 0.0)) return;
        std::size_t active = 0;
        for (std::size_t k = 0; k < m_.C; ++k) {
            const double a = P[3 + k], b = Q[3 + k], d = R[3 + k];
            if (a < 0.0 && b < 0.0 && d < 0.0) return;
            if (a < 0.0 || b < 0.0 || d < 0.0) c_[active++] = {a, b, d};
        }
        if (active == 0) {
            poly_[0] = {P[0], P[1]}, poly_[1] = {Q[0], Q[1]}, poly_[2] = {R[0], R[1]};
            out_.add(poly_.data(), 3, e, gradientOf(P, Q, R, (poly_[0] + poly_[1] + poly_[2]) / 3.0));
            out_.pupilCells += area;
            return;
        }
        const double share = clipper_.clip(c_.data(), active);
        if (share <= 0.0) return;
        out_.pupilCells += area * share;
        for (std::size_t q = 0; q < clipper_.size(); ++q) {
            const glm::dvec3& b = clipper_[q];
            poly_[q] = {b.x * P[0] + b.y * Q[0] + b.z * R[0], b.x * P[1] + b.y * Q[1] + b.z * R[1]};
        }
        out_.add(poly_.data(), clipper_.size(), e * share,
                 gradientOf(P, Q, R, centroid(poly_.data(), clipper_.size())));
    }

    const std::vector<std::array<double, 4>>& weightsFor(int K) {
        auto& cr = weights_[K];
        if (cr.empty())
            for (int a = 0; a <= K; ++a) {
                cr.push_back(catmullRom(double(a) / K));
                slopes_[K].push_back(catmullRomSlope(double(a) / K));
            }
        return cr;
    }

    // Attribute z of the bicubic surface over the current cell's 4 x 4 neighbourhood nb_.
    double bicubic(const std::array<double, 4>& wx, const std::array<double, 4>& wy, std::size_t z) const {
        double acc = 0.0;
        for (int q = 0; q < 4; ++q)
            acc += wy[q] * (wx[0] * nb_[q * 4][z] + wx[1] * nb_[q * 4 + 1][z] + wx[2] * nb_[q * 4 + 2][z] +
                            wx[3] * nb_[q * 4 + 3][z]);
        return acc;
    }

    const MeshVertices& m_;
    const MeshInstance& in_;
    const ShapedRenderSettings& settings_;
    const trace::ImageFrame& frame_;
    const double flux_;
    ShapedPolygons& out_;
    const double tolerance_; ///< irradianceSplit's, weight per pixel^2
    const int kEdge_;        ///< sub-cells per side of a bilinear cell an edge crosses
    const std::array<double, 4> half_ = catmullRom(0.5), halfSlope_ = catmullRomSlope(0.5);
    std::vector<std::vector<std::array<double, 4>>> weights_, slopes_; ///< Catmull-Rom at a / K, per K
    std::array<const double*, 16> nb_{};
    std::vector<double> sub_;
    TriangleClipper clipper_;
    std::array<std::array<double, 3>, kMaxConstraints> c_{};
    std::array<glm::dvec2, kMaxPolygon> poly_{};
};

} // namespace

void meshPolygons(const ShapedTable& table, const MeshInstance& in, std::size_t w, const Placement& placement,
                  double flux, const trace::ImageFrame& frame, const ShapedRenderSettings& settings,
                  ShapedPolygons& out) {
    const MeshVertices m = placeMesh(table, in, w, placement, frame);
    if (!m.lit()) return;
    CellCutter cutter(m, in, settings, frame, flux, out);
    for (int j = 0; j < m.n; ++j)
        for (int i = 0; i < m.n; ++i) cutter.cell(i, j);
}

void ShapedPolygons::add(const glm::dvec2* p, std::size_t n, double e, const glm::dvec2& gradient) {
    double area2 = 0.0;
    for (std::size_t i = 0; i < n; ++i) area2 += p[i].x * p[(i + 1) % n].y - p[(i + 1) % n].x * p[i].y;
    if (std::isfinite(area2)) areaPx += 0.5 * std::abs(area2);
    Poly q{static_cast<std::uint32_t>(vertices.size()), static_cast<std::uint32_t>(n),
           std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(), e};
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec2 v(p[i]);
        vertices.push_back(v);
        q.yMin = std::min(q.yMin, v.y);
        q.yMax = std::max(q.yMax, v.y);
    }
    // Gradients are stored from the first polygon that has one (the earlier ones 0).
    const bool slope = gradient.x != 0.0 || gradient.y != 0.0;
    if (slope && gradients.size() < polys.size()) gradients.assign(polys.size(), glm::vec2(0.0f));
    if (slope || !gradients.empty()) gradients.push_back(glm::vec2(gradient));
    polys.push_back(q);
    energy += e;
    ++triangles;
}

} // namespace ff::ghosts
