// A shaped ghost instance's mesh placed in the frame (mesh_vertices.h).

#include "ghosts/mesh_vertices.h"

#include "ghosts/mesh_clip.h"

#include <algorithm>
#include <cmath>
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

} // namespace

MeshVertices placeMesh(const ShapedTable& table, const MeshInstance& in, std::size_t w, const Placement& placement,
                       const trace::ImageFrame& frame) {
    MeshVertices m = table.twoDimensional() ? interpolateFields(table, in, w, placement, frame)
                                            : interpolateAngles(table, in, w, placement, frame);
    if (m.lit()) addJacobians(m);
    return m;
}

} // namespace ff::ghosts
