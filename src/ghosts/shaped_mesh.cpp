// A ghost's mesh at one wavelength, interpolated between table angles and cut into the clipped
// polygons it is drawn as (shaped_mesh.h).

#include "ghosts/shaped_mesh.h"

#include "core/error.h"
#include "core/units.h"
#include "ghosts/mesh_clip.h"
#include "ghosts/shaped_ghosts.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

namespace ff::ghosts {

namespace {

// Per-blade edge lines of an iris turned by `turn`: c = apothem - n . p (mm, >= 0 inside). A circle
// is one constraint, radius - |p|.
struct IrisEdges {
    std::vector<glm::dvec2> normals;
    double apothem = 0.0, radius = 0.0;
    // Turned by `turn`, then mirrored (mirrorX, mirrorY: +-1; a mirror is its own inverse).
    IrisEdges(const trace::Iris& iris, double turn, double mirrorX = 1.0, double mirrorY = 1.0) : radius(iris.radius) {
        if (iris.blades < 3) return;
        const double sector = 2.0 * std::numbers::pi / iris.blades;
        apothem = iris.circumradius * std::cos(0.5 * sector);
        for (int k = 0; k < iris.blades; ++k) {
            const double phi = iris.rotationRad + turn + (k + 0.5) * sector;
            normals.push_back({mirrorX * std::cos(phi), mirrorY * std::sin(phi)});
        }
    }
    std::size_t count() const { return normals.empty() ? 1 : normals.size(); }
    double value(std::size_t k, double x, double y) const {
        if (normals.empty()) return radius - std::hypot(x, y);
        return apothem - (normals[k].x * x + normals[k].y * y);
    }
};

// Catmull-Rom weights of the four samples around a position u in [0, 1] between the middle two.
std::array<double, 4> catmullRom(double u) {
    const double u2 = u * u, u3 = u2 * u;
    return {0.5 * (-u + 2 * u2 - u3), 0.5 * (2 - 5 * u2 + 3 * u3), 0.5 * (u + 4 * u2 - 3 * u3), 0.5 * (-u2 + u3)};
}

// Their derivatives in u.
std::array<double, 4> catmullRomSlope(double u) {
    const double u2 = u * u;
    return {0.5 * (-1 + 4 * u - 3 * u2), 0.5 * (-10 * u + 9 * u2), 0.5 * (1 + 8 * u - 9 * u2), 0.5 * (-2 * u + 3 * u2)};
}

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

// One instance's mesh at one wavelength, interpolated in angle and placed in the frame: per vertex S
// doubles, pixel x, y, weight, the C constraints' values, then the map's Jacobian (pixels^2 per cell;
// NaN where it cannot be taken).
struct MeshVertices {
    int n = 0; ///< cells per side
    std::size_t C = 0, J = 0, S = 0;
    std::vector<double> attr;
    std::vector<char> ok; ///< the vertex's ray lands
    double xMin = std::numeric_limits<double>::infinity(), xMax = -xMin, yMin = xMin, yMax = -xMin;

    std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * (n + 1) + i; }
    const double* at(std::size_t v) const { return &attr[v * S]; }
    bool lit() const { return xMax >= xMin; }
};

// Catmull-Rom weights at u between samples 1 and 2 of four, a missing outer sample (0 or 3: beyond
// the table's ends, or without light) being the linear extrapolation of the two inner ones
// (2 p1 - p2, 2 p2 - p1), folded into the weights.
std::array<double, 4> foldedCatmullRom(double u, bool before, bool after) {
    std::array<double, 4> w = catmullRom(u);
    if (!before) w = {0.0, w[1] + 2.0 * w[0], w[2] - w[0], w[3]};
    if (!after) w = {w[0], w[1] - w[3], w[2] + 2.0 * w[3], 0.0};
    return w;
}

// An instance's mesh in the frame: every in.decimation-th vertex of the ghost's grid, its
// attributes interpolated between the table's fields (interpolateAngles, interpolateFields), placed
// as `placement` says in the frame's pixels, the iris clipped in the table's frame seen the inverse
// way; the Jacobians left NaN (addJacobians).
class VertexPlacer {
  public:
    VertexPlacer(const ShapedTable& table, const MeshInstance& in, const Placement& placement,
                 const trace::ImageFrame& frame)
        : gh_(table.ghosts[in.ghost]), frame_(frame),
          dec_(in.decimation > 0 && gh_.grid % in.decimation == 0 ? in.decimation : 1),
          cs_(std::cos(placement.azimuthRad)), sn_(std::sin(placement.azimuthRad)), mx_(placement.mirrorX),
          my_(placement.mirrorY), iris_(table.iris, -placement.azimuthRad, placement.mirrorX, placement.mirrorY) {
        nA_ = gh_.apertureSteps.size();
        m_.n = gh_.grid / dec_;
        m_.C = std::min(kMaxConstraints, nA_ + gh_.stopCrossings * iris_.count());
        m_.J = 3 + m_.C;
        m_.S = 4 + m_.C;
        const std::size_t V = static_cast<std::size_t>(m_.n + 1) * (m_.n + 1);
        m_.attr.assign(V * m_.S, 0.0);
        m_.ok.assign(V, 0);
        for (std::size_t v = 0; v < V; ++v) m_.attr[v * m_.S + m_.J] = std::numeric_limits<double>::quiet_NaN();
    }

    std::size_t vertices() const { return m_.ok.size(); }
    // The offset of output vertex v's attributes in a mesh's data.
    std::size_t source(std::size_t v) const {
        const int n = m_.n;
        return (v / (n + 1) * (gh_.grid + 1) + v % (n + 1)) * static_cast<std::size_t>(dec_) * gh_.stride();
    }
    // Vertex v from its interpolated attributes: value(z) for attribute z of the ghost's stride.
    template <typename Value>
    void place(std::size_t v, Value&& value) {
        const double x = value(0), y = value(1);
        const glm::dvec2 px = frame_.sensorToPixel(mx_ * (cs_ * x - sn_ * y), my_ * (sn_ * x + cs_ * y));
        double* o = &m_.attr[v * m_.S];
        o[0] = px.x;
        o[1] = px.y;
        // A decimated cell holds dec^2 of the mesh's cells: its weight (flux per cell) scales so.
        o[2] = double(dec_) * dec_ * value(2);
        m_.ok[v] = 1;
        std::size_t k = 0;
        for (; k < nA_ && k < m_.C; ++k) o[3 + k] = value(3 + k);
        for (std::size_t s = 0; s < gh_.stopCrossings; ++s) {
            const double sx = value(3 + nA_ + 2 * s);
            const double sy = value(4 + nA_ + 2 * s);
            for (std::size_t b = 0; b < iris_.count() && k < m_.C; ++b) o[3 + k++] = iris_.value(b, sx, sy);
        }
        m_.xMin = std::min(m_.xMin, px.x), m_.xMax = std::max(m_.xMax, px.x), m_.yMin = std::min(m_.yMin, px.y),
        m_.yMax = std::max(m_.yMax, px.y);
    }
    MeshVertices take() { return std::move(m_); }

  private:
    const ShapedGhost& gh_;
    const trace::ImageFrame& frame_;
    const int dec_;
    const double cs_, sn_, mx_, my_;
    const IrisEdges iris_;
    std::size_t nA_ = 0;
    MeshVertices m_;
};

// The mesh between the table's angles a0 and a0 + 1 at fraction in.t (Catmull-Rom in angle).
MeshVertices interpolateAngles(const ShapedTable& table, const MeshInstance& in, std::size_t w,
                               const Placement& placement, const trace::ImageFrame& frame) {
    const ShapedGhost& gh = table.ghosts[in.ghost];
    const int A = table.angles();
    const ShapedMesh& m0 = gh.meshes[w][in.a0];
    const ShapedMesh& m1 = gh.meshes[w][std::min(in.a0 + 1, A - 1)];
    // The angles on either side for the cubic interpolation (null at the table's ends).
    const ShapedMesh* mb = in.a0 > 0 ? &gh.meshes[w][in.a0 - 1] : nullptr;
    const ShapedMesh* ma = in.a0 + 2 < A ? &gh.meshes[w][in.a0 + 2] : nullptr;
    if (mb && mb->data.empty()) mb = nullptr;
    if (ma && ma->data.empty()) ma = nullptr;
    VertexPlacer placer(table, in, placement, frame);
    const std::array<double, 4> wc = foldedCatmullRom(in.t, mb != nullptr, ma != nullptr);
    // A mesh without light is a mesh of lost rays.
    const std::vector<float> lost(gh.stride(), std::numeric_limits<float>::quiet_NaN());
    for (std::size_t v = 0; v < placer.vertices(); ++v) {
        const std::size_t src = placer.source(v);
        const float* p = m0.data.empty() ? lost.data() : &m0.data[src];
        const float* q = m1.data.empty() ? lost.data() : &m1.data[src];
        const float* pb = mb ? &mb->data[src] : p;
        const float* qa = ma ? &ma->data[src] : q;
        // A ray lost at one of the two angles is taken from the other up to the middle between
        // them, and lost beyond it; where it is lost at one of the outer two, the interpolation is
        // linear.
        double t = in.t;
        if (std::isnan(p[0]) || std::isnan(q[0])) {
            if (std::isnan(p[0]) == std::isnan(q[0]) || std::isnan(p[0]) == (t < 0.5)) continue;
            t = std::isnan(p[0]) ? 1.0 : 0.0;
        }
        const bool cubic = t > 0.0 && t < 1.0 && !std::isnan(pb[0]) && !std::isnan(qa[0]);
        placer.place(v, [&, t](std::size_t z) {
            if (cubic) return wc[0] * pb[z] + wc[1] * p[z] + wc[2] * q[z] + wc[3] * qa[z];
            return t == 0.0 ? double(p[z]) : t == 1.0 ? double(q[z]) : (1.0 - t) * p[z] + t * q[z];
        });
    }
    return placer.take();
}

// The mesh between the two-dimensional table's fields (a0, b0) and (a0 + 1, b0 + 1) at fractions
// (in.t, in.s): bicubic Catmull-Rom over the 4 x 4 fields around them (folded at the grid's ends,
// as in angle); bilinear where a ray is lost at one of those fields or a mesh has no light; where it
// is lost at one of the four nearest, bilinear over those where it lands, renormalised and moved
// with the mesh, as long as the nearest of the four keeps it (lost otherwise, as between two
// angles).
MeshVertices interpolateFields(const ShapedTable& table, const MeshInstance& in, std::size_t w,
                               const Placement& placement, const trace::ImageFrame& frame) {
    const ShapedGhost& gh = table.ghosts[in.ghost];
    const int X = table.fieldGrid.x, Y = table.fieldGrid.y;
    const auto meshAt = [&](int i, int j) -> const ShapedMesh* {
        if (i < 0 || j < 0 || i >= X || j >= Y) return nullptr;
        const ShapedMesh& m = gh.meshes[w][static_cast<std::size_t>(j) * X + i];
        return m.data.empty() ? nullptr : &m;
    };
    // The stencil [row][column], rows along y from b0 - 1, columns along x from a0 - 1, and each
    // field's direct flux (the weights' reference: the weight interpolated is the weight times it,
    // over its interpolation).
    std::array<std::array<const ShapedMesh*, 4>, 4> st{};
    std::array<std::array<double, 4>, 4> direct{};
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            st[r][c] = meshAt(in.a0 - 1 + c, in.b0 - 1 + r);
            const int i = in.a0 - 1 + c, j = in.b0 - 1 + r;
            if (i >= 0 && j >= 0 && i < X && j < Y && w < table.directFlux.size())
                direct[r][c] = table.directFlux[w][static_cast<std::size_t>(j) * X + i];
        }
    // The weight (attribute 2) as sum c D w / sum c D over the interpolation's coefficients c and
    // the fields' direct fluxes D; where those are all 0, as the other attributes.
    const auto ratio = [](double plain, double weighted, double directs) {
        return directs > 0.0 ? weighted / directs : plain;
    };
    const std::array<double, 4> wx = foldedCatmullRom(in.t, in.a0 > 0, in.a0 + 2 < X),
                                wy = foldedCatmullRom(in.s, in.b0 > 0, in.b0 + 2 < Y);
    VertexPlacer placer(table, in, placement, frame);
    const std::array<double, 2> bx{1.0 - in.t, in.t}, by{1.0 - in.s, in.s};
    const int nearX = in.t < 0.5 ? 1 : 2, nearY = in.s < 0.5 ? 1 : 2;
    // How the mesh moves between the four nearest fields: each one's mean landing point over the
    // vertices that land at all four (o), and their bilinear interpolation (moved). A ray lost at
    // some of them lands where it lands at the others, moved with the mesh: a line focus (the
    // cylinders' streak) stays on its line instead of landing on a neighbouring field's.
    std::array<glm::dvec2, 4> o{};
    glm::dvec2 moved(0.0);
    {
        std::size_t common = 0;
        for (std::size_t v = 0; v < placer.vertices(); ++v) {
            const std::size_t src = placer.source(v);
            bool all = true;
            for (int k = 0; k < 4 && all; ++k) {
                const ShapedMesh* m = st[1 + k / 2][1 + k % 2];
                all = m && !std::isnan(m->data[src]);
            }
            if (!all) continue;
            ++common;
            for (int k = 0; k < 4; ++k) {
                const float* q = &st[1 + k / 2][1 + k % 2]->data[src];
                o[k] += glm::dvec2(q[0], q[1]);
            }
        }
        double total = 0.0;
        for (int k = 0; k < 4 && common > 0; ++k) {
            o[k] /= double(common);
            moved += by[k / 2] * bx[k % 2] * o[k];
            total += by[k / 2] * bx[k % 2];
        }
        if (total > 0.0) moved /= total;
    }
    std::array<std::array<const float*, 4>, 4> p{};
    for (std::size_t v = 0; v < placer.vertices(); ++v) {
        const std::size_t src = placer.source(v);
        bool cubic = true;
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) {
                const bool used = wy[r] != 0.0 && wx[c] != 0.0;
                p[r][c] = st[r][c] && !std::isnan(st[r][c]->data[src]) ? &st[r][c]->data[src] : nullptr;
                if (used && !p[r][c]) cubic = false;
            }
        if (!p[nearY][nearX]) continue;
        if (cubic) {
            placer.place(v, [&](std::size_t z) {
                double acc = 0.0, weighted = 0.0, directs = 0.0;
                for (int r = 0; r < 4; ++r) {
                    double row = 0.0;
                    for (int c = 0; c < 4; ++c)
                        if (wx[c] != 0.0 && wy[r] != 0.0) {
                            row += wx[c] * p[r][c][z];
                            weighted += wy[r] * wx[c] * direct[r][c] * p[r][c][z];
                            directs += wy[r] * wx[c] * direct[r][c];
                        }
                    acc += wy[r] * row;
                }
                return z == 2 ? ratio(acc, weighted, directs) : acc;
            });
            continue;
        }
        double total = 0.0;
        for (int r = 0; r < 2; ++r)
            for (int c = 0; c < 2; ++c)
                if (p[1 + r][1 + c]) total += by[r] * bx[c];
        placer.place(v, [&](std::size_t z) {
            double acc = 0.0, weighted = 0.0, directs = 0.0;
            for (int r = 0; r < 2; ++r)
                for (int c = 0; c < 2; ++c)
                    if (p[1 + r][1 + c] && by[r] * bx[c] != 0.0) {
                        const double b = by[r] * bx[c], shift = z == 0 ? o[2 * r + c].x : z == 1 ? o[2 * r + c].y : 0.0;
                        acc += b * (p[1 + r][1 + c][z] - shift);
                        weighted += b * direct[1 + r][1 + c] * p[1 + r][1 + c][z];
                        directs += b * direct[1 + r][1 + c];
                    }
            if (z == 2) return ratio(acc / total, weighted, directs);
            return acc / total + (z == 0 ? moved.x : z == 1 ? moved.y : 0.0);
        });
    }
    return placer.take();
}

// The Jacobian at each vertex by central differences (one-sided at the grid's border or next to a
// lost ray): the weight over it is the irradiance there, which shapes each element's density.
void addJacobians(MeshVertices& m) {
    const int n = m.n;
    auto at = [&](int a, int b) -> const double* {
        if (a < 0 || b < 0 || a > n || b > n) return nullptr;
        const std::size_t u = m.index(a, b);
        return m.ok[u] ? m.at(u) : nullptr;
    };
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const std::size_t v = m.index(i, j);
            if (!m.ok[v]) continue;
            auto difference = [&](int di, int dj) {
                const double *lo = at(i - di, j - dj), *hi = at(i + di, j + dj), *mid = m.at(v);
                if (lo && hi) return glm::dvec2(0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1]));
                if (hi) return glm::dvec2(hi[0] - mid[0], hi[1] - mid[1]);
                if (lo) return glm::dvec2(mid[0] - lo[0], mid[1] - lo[1]);
                return glm::dvec2(std::numeric_limits<double>::quiet_NaN());
            };
            const glm::dvec2 du = difference(1, 0), dv = difference(0, 1);
            m.attr[v * m.S + m.J] = du.x * dv.y - du.y * dv.x;
        }
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
    MeshVertices m = table.twoDimensional() ? interpolateFields(table, in, w, placement, frame)
                                            : interpolateAngles(table, in, w, placement, frame);
    if (!m.lit()) return;
    addJacobians(m);
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
