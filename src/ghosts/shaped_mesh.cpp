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
    IrisEdges(const trace::Iris& iris, double turn) : radius(iris.radius) {
        if (iris.blades < 3) return;
        const double sector = 2.0 * std::numbers::pi / iris.blades;
        apothem = iris.circumradius * std::cos(0.5 * sector);
        for (int k = 0; k < iris.blades; ++k) {
            const double phi = iris.rotationRad + turn + (k + 0.5) * sector;
            normals.push_back({std::cos(phi), std::sin(phi)});
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

} // namespace

void meshPolygons(const ShapedTable& table, const MeshInstance& in, std::size_t w, double azimuthRad, double flux,
                  const trace::ImageFrame& frame, const ShapedRenderSettings& settings, ShapedPolygons& out) {
    const ShapedGhost& gh = table.ghosts[in.ghost];
    const int A = table.angles();
    const ShapedMesh& m0 = gh.meshes[w][in.a0];
    const ShapedMesh& m1 = gh.meshes[w][std::min(in.a0 + 1, A - 1)];
    // The angles on either side for the cubic interpolation (null at the table's ends).
    const ShapedMesh* mb = in.a0 > 0 ? &gh.meshes[w][in.a0 - 1] : nullptr;
    const ShapedMesh* ma = in.a0 + 2 < A ? &gh.meshes[w][in.a0 + 2] : nullptr;
    if (mb && mb->data.empty()) mb = nullptr;
    if (ma && ma->data.empty()) ma = nullptr;
    const std::size_t stride = gh.stride(), nA = gh.apertureSteps.size();
    const int dec = in.decimation > 0 && gh.grid % in.decimation == 0 ? in.decimation : 1;
    const int n = gh.grid / dec;
    const std::size_t V = static_cast<std::size_t>(n + 1) * (n + 1);
    // A decimated cell holds dec^2 of the mesh's cells: its weight (flux per cell) scales so.
    const double cellWeight = double(dec) * dec;
    const double cs = std::cos(azimuthRad), sn = std::sin(azimuthRad);
    const IrisEdges iris(table.iris, -azimuthRad);
    const std::size_t C = std::min(kMaxConstraints, nA + gh.stopCrossings * iris.count());
    // Catmull-Rom weights in angle; a missing neighbour beyond the table's ends is the linear
    // extrapolation of the two inner angles (2 p0 - p1), folded into the weights.
    std::array<double, 4> wc = catmullRom(in.t);
    if (!mb) wc = {0.0, wc[1] + 2.0 * wc[0], wc[2] - wc[0], wc[3]};
    if (!ma) wc = {wc[0], wc[1] - wc[3], wc[2] + 2.0 * wc[3], 0.0};

    // Per vertex: pixel x, y, weight, the constraints' values, then the map's Jacobian (pixels^2 per
    // cell; NaN where it cannot be taken).
    const bool linear = settings.linearDensity;
    const std::size_t J = 3 + C, S = 4 + C;
    std::vector<double> attr(V * S, 0.0);
    std::vector<char> ok(V, 0);
    double xMin = std::numeric_limits<double>::infinity(), xMax = -xMin, yMin = xMin, yMax = -xMin;
    // A mesh without light is a mesh of lost rays.
    const std::vector<float> lost(stride, std::numeric_limits<float>::quiet_NaN());
    for (std::size_t v = 0; v < V; ++v) {
        const std::size_t src = (v / (n + 1) * (gh.grid + 1) + v % (n + 1)) * static_cast<std::size_t>(dec) * stride;
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
        auto interpolate = [&, t](std::size_t z) {
            if (cubic) return wc[0] * pb[z] + wc[1] * p[z] + wc[2] * q[z] + wc[3] * qa[z];
            return t == 0.0 ? double(p[z]) : t == 1.0 ? double(q[z]) : (1.0 - t) * p[z] + t * q[z];
        };
        const double x = interpolate(0), y = interpolate(1);
        const glm::dvec2 px = frame.sensorToPixel(cs * x - sn * y, sn * x + cs * y);
        double* o = &attr[v * S];
        o[0] = px.x;
        o[1] = px.y;
        o[2] = cellWeight * interpolate(2);
        ok[v] = 1;
        std::size_t k = 0;
        for (; k < nA && k < C; ++k) o[3 + k] = interpolate(3 + k);
        for (std::size_t s = 0; s < gh.stopCrossings; ++s) {
            const double sx = interpolate(3 + nA + 2 * s);
            const double sy = interpolate(4 + nA + 2 * s);
            for (std::size_t b = 0; b < iris.count() && k < C; ++b) o[3 + k++] = iris.value(b, sx, sy);
        }
        xMin = std::min(xMin, px.x), xMax = std::max(xMax, px.x), yMin = std::min(yMin, px.y),
        yMax = std::max(yMax, px.y);
    }
    if (!(xMax >= xMin)) return;
    // The Jacobian at each vertex by central differences (one-sided at the grid's border or next to a
    // lost ray): the weight over it is the irradiance there, which shapes each element's density.
    for (std::size_t v = 0; v < V; ++v) {
        attr[v * S + J] = std::numeric_limits<double>::quiet_NaN();
        if (!ok[v]) continue;
        const int i = static_cast<int>(v % (n + 1)), j = static_cast<int>(v / (n + 1));
        auto difference = [&](int di, int dj) {
            auto at = [&](int a, int b) -> const double* {
                if (a < 0 || b < 0 || a > n || b > n) return nullptr;
                const std::size_t u = static_cast<std::size_t>(b) * (n + 1) + a;
                return ok[u] ? &attr[u * S] : nullptr;
            };
            const double *lo = at(i - di, j - dj), *hi = at(i + di, j + dj), *mid = &attr[v * S];
            if (lo && hi) return glm::dvec2(0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1]));
            if (hi) return glm::dvec2(hi[0] - mid[0], hi[1] - mid[1]);
            if (lo) return glm::dvec2(mid[0] - lo[0], mid[1] - lo[1]);
            return glm::dvec2(std::numeric_limits<double>::quiet_NaN());
        };
        const glm::dvec2 du = difference(1, 0), dv = difference(0, 1);
        attr[v * S + J] = du.x * dv.y - du.y * dv.x;
    }
    // Cells are split into k x k sub-cells placed by bicubic (Catmull-Rom) interpolation of the grid,
    // k growing until the bicubic surface, and the aperture edges crossing the cell, lie within
    // in.flatnessPx of the sub-cells' flat triangles (the deviation falls as 1 / k^2). Cells next to
    // the grid's border or a lost ray are interpolated bilinearly; those an edge crosses are cut
    // until a sub-cell spans about settings.subcellPx pixels.
    const double cellPx = std::max(xMax - xMin, yMax - yMin) / n;
    const int kEdge = std::clamp(static_cast<int>(std::ceil(cellPx / settings.subcellPx)), 1, settings.maxSubdivision);
    TriangleClipper clipper;
    std::array<std::array<double, 3>, kMaxConstraints> c{};
    std::array<glm::dvec2, kMaxPolygon> poly{};
    // A triangle's density: the plane through its vertices' irradiances (weight / |Jacobian|) where
    // the map keeps its orientation over it, as a gradient relative to the plane's value at `at`
    // (the centroid of what is drawn); 0 (uniform) where it folds or a Jacobian is missing.
    auto gradientOf = [&](const double* P, const double* Q, const double* R, const glm::dvec2& at) {
        if (!linear) return glm::dvec2(0.0);
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
    };
    auto centroid = [](const glm::dvec2* p, std::size_t count) {
        double a = 0.0;
        glm::dvec2 sum(0.0);
        for (std::size_t k = 0; k < count; ++k) {
            const glm::dvec2 &u = p[k], &v = p[(k + 1) % count];
            const double cross = u.x * v.y - v.x * u.y;
            a += cross;
            sum += (u + v) * cross;
        }
        return a != 0.0 ? sum / (3.0 * a) : p[0];
    };
    auto triangle = [&](const double* P, const double* Q, const double* R, double area) {
        const double e = flux * area * (P[2] + Q[2] + R[2]) / 3.0;
        if (!(e > 0.0)) return;
        std::size_t active = 0;
        for (std::size_t k = 0; k < C; ++k) {
            const double a = P[3 + k], b = Q[3 + k], d = R[3 + k];
            if (a < 0.0 && b < 0.0 && d < 0.0) return;
            if (a < 0.0 || b < 0.0 || d < 0.0) c[active++] = {a, b, d};
        }
        if (active == 0) {
            poly[0] = {P[0], P[1]}, poly[1] = {Q[0], Q[1]}, poly[2] = {R[0], R[1]};
            out.add(poly.data(), 3, e, gradientOf(P, Q, R, (poly[0] + poly[1] + poly[2]) / 3.0));
            out.pupilCells += area;
            return;
        }
        const double share = clipper.clip(c.data(), active);
        if (share <= 0.0) return;
        out.pupilCells += area * share;
        for (std::size_t q = 0; q < clipper.size(); ++q) {
            const glm::dvec3& b = clipper[q];
            poly[q] = {b.x * P[0] + b.y * Q[0] + b.z * R[0], b.x * P[1] + b.y * Q[1] + b.z * R[1]};
        }
        out.add(poly.data(), clipper.size(), e * share, gradientOf(P, Q, R, centroid(poly.data(), clipper.size())));
    };
    std::vector<std::vector<std::array<double, 4>>> weights(settings.maxSubdivision + 1),
        slopes(settings.maxSubdivision + 1);
    auto weightsFor = [&](int K) -> const std::vector<std::array<double, 4>>& {
        auto& cr = weights[K];
        if (cr.empty())
            for (int a = 0; a <= K; ++a) {
                cr.push_back(catmullRom(double(a) / K));
                slopes[K].push_back(catmullRomSlope(double(a) / K));
            }
        return cr;
    };
    std::vector<double> sub;
    std::array<const double*, 16> nb{};
    auto bicubic = [&](const std::array<double, 4>& wx, const std::array<double, 4>& wy, std::size_t z) {
        double acc = 0.0;
        for (int q = 0; q < 4; ++q)
            acc += wy[q] * (wx[0] * nb[q * 4][z] + wx[1] * nb[q * 4 + 1][z] + wx[2] * nb[q * 4 + 2][z] +
                            wx[3] * nb[q * 4 + 3][z]);
        return acc;
    };
    const auto half = catmullRom(0.5), halfSlope = catmullRomSlope(0.5);
    // The instance's brightest pixel, estimated (weight per pixel^2): the largest mean irradiance of a
    // cell the apertures leave whole, over at least a pixel (a smaller cell's flux lands in about one);
    // of any cell where none is whole.
    double peakWhole = 0.0, peakAny = 0.0;
    for (int j = 0; j < n && std::isfinite(in.irradianceError); ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t v00 = static_cast<std::size_t>(j) * (n + 1) + i, v10 = v00 + 1, v01 = v00 + n + 1,
                              v11 = v01 + 1;
            if (!(ok[v00] && ok[v10] && ok[v01] && ok[v11])) continue;
            const double *a = &attr[v00 * S], *b = &attr[v10 * S], *d = &attr[v01 * S], *e = &attr[v11 * S];
            const double areaPx = 0.5 * std::abs((e[0] - a[0]) * (d[1] - b[1]) - (d[0] - b[0]) * (e[1] - a[1]));
            const double mean = 0.25 * (a[2] + b[2] + d[2] + e[2]) / std::max(areaPx, 1.0);
            if (!std::isfinite(mean)) continue;
            bool whole = true;
            for (std::size_t k = 0; k < C && whole; ++k)
                whole = a[3 + k] >= 0.0 && b[3 + k] >= 0.0 && d[3 + k] >= 0.0 && e[3 + k] >= 0.0;
            peakAny = std::max(peakAny, mean);
            if (whole) peakWhole = std::max(peakWhole, mean);
        }
    const double tolerance = in.irradianceError * (peakWhole > 0.0 ? peakWhole : peakAny);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t v00 = static_cast<std::size_t>(j) * (n + 1) + i, v10 = v00 + 1, v01 = v00 + n + 1,
                              v11 = v01 + 1;
            const bool all = ok[v00] && ok[v10] && ok[v01] && ok[v11];
            // The 4 x 4 neighbourhood; bilinear where it leaves the grid or meets a lost ray.
            bool cubic = all;
            for (int q = -1; q <= 2 && cubic; ++q)
                for (int r = -1; r <= 2 && cubic; ++r) {
                    const int x = i + r, y = j + q;
                    if (x < 0 || y < 0 || x > n || y > n || !ok[static_cast<std::size_t>(y) * (n + 1) + x])
                        cubic = false;
                    else
                        nb[(q + 1) * 4 + (r + 1)] = &attr[(static_cast<std::size_t>(y) * (n + 1) + x) * S];
                }
            // A cell with its four corners outside one aperture is dark (the margins are smooth at
            // the grid's scale; a curved edge bulging into it from outside would carry a sliver).
            bool dark = false;
            for (std::size_t k = 0; k < C && all && !dark; ++k)
                dark = attr[v00 * S + 3 + k] < 0.0 && attr[v10 * S + 3 + k] < 0.0 && attr[v01 * S + 3 + k] < 0.0 &&
                       attr[v11 * S + 3 + k] < 0.0;
            if (dark) continue;
            int K = 1;
            // A cell that lies a cell's size beyond the frame (its bicubic surface cannot bulge
            // further) stays flat: its light only counts as leaving the frame.
            const double* c00 = &attr[v00 * S];
            const double* c10 = &attr[v10 * S];
            const double* c01 = &attr[v01 * S];
            const double* c11 = &attr[v11 * S];
            const double cx0 = std::min({c00[0], c10[0], c01[0], c11[0]}),
                         cx1 = std::max({c00[0], c10[0], c01[0], c11[0]}),
                         cy0 = std::min({c00[1], c10[1], c01[1], c11[1]}),
                         cy1 = std::max({c00[1], c10[1], c01[1], c11[1]});
            const double reach = 1.0 + std::max(cx1 - cx0, cy1 - cy0);
            const bool beyond =
                all && (cx1 < -reach || cy1 < -reach || cx0 > frame.width + reach || cy0 > frame.height + reach);
            if (all && !beyond) {
                // Deviation of the bicubic surface from the flat cell at its centre, in pixels: of
                // the landing point, and of where a cutting aperture's edge (a constraint's zero)
                // crosses the cell (the constraint's deviation over its gradient across the cell).
                auto deviation = [&](std::size_t z) {
                    const double flat =
                        0.25 * (attr[v00 * S + z] + attr[v10 * S + z] + attr[v01 * S + z] + attr[v11 * S + z]);
                    return std::abs(bicubic(half, half, z) - flat);
                };
                bool edge = false;
                const double landing = cubic ? std::max(deviation(0), deviation(1)) : 0.0;
                double edgeDev = 0.0;
                const double sizePx = std::max(
                    {std::abs(attr[v11 * S] - attr[v00 * S]), std::abs(attr[v10 * S] - attr[v01 * S]),
                     std::abs(attr[v11 * S + 1] - attr[v00 * S + 1]), std::abs(attr[v10 * S + 1] - attr[v01 * S + 1])});
                for (std::size_t k = 0; k < C; ++k) {
                    const double a = attr[v00 * S + 3 + k], b = attr[v10 * S + 3 + k], d = attr[v01 * S + 3 + k],
                                 e = attr[v11 * S + 3 + k];
                    const double lo = std::min({a, b, d, e}), hi = std::max({a, b, d, e});
                    if (!(lo < 0.0 && hi >= 0.0)) continue;
                    edge = true;
                    if (cubic) edgeDev = std::max(edgeDev, deviation(3 + k) * sizePx / (hi - lo));
                }
                const double edgeFlatness = in.edgeFlatnessPx > 0.0 ? in.edgeFlatnessPx : in.flatnessPx;
                if (edge && !cubic)
                    K = kEdge;
                else
                    K = std::clamp(static_cast<int>(
                                       std::ceil(std::sqrt(std::max(landing / in.flatnessPx, edgeDev / edgeFlatness)))),
                                   1, settings.maxSubdivision);
                // Then the error the elements' density leaves in the pixels (irradianceSplit): the
                // irradiance at the corners (their Jacobians) and at the centre (the bicubic's own).
                if (cubic && sizePx > 0.0 && tolerance > 0.0 && std::isfinite(tolerance)) {
                    CellIrradiance ci;
                    ci.sizePx = sizePx;
                    ci.areaPx =
                        0.5 * std::abs((c11[0] - c00[0]) * (c01[1] - c10[1]) - (c01[0] - c10[0]) * (c11[1] - c00[1]));
                    const double jc = bicubic(halfSlope, half, 0) * bicubic(half, halfSlope, 1) -
                                      bicubic(half, halfSlope, 0) * bicubic(halfSlope, half, 1);
                    ci.centre = std::max(0.0, bicubic(half, half, 2)) / std::abs(jc);
                    const std::array<const double*, 4> corners4{c00, c10, c01, c11};
                    bool positive = jc > 0.0, negative = jc < 0.0;
                    for (int q = 0; q < 4; ++q) {
                        ci.corner[q] = std::max(0.0, corners4[q][2]) / std::abs(corners4[q][J]);
                        positive = positive && corners4[q][J] > 0.0;
                        negative = negative && corners4[q][J] < 0.0;
                    }
                    ci.fold = !(positive || negative);
                    K = std::max(K, irradianceSplit(ci, tolerance, linear, settings.maxSubdivision));
                }
            }
            if (K == 1) {
                const std::array<std::size_t, 4> corners{v00, v10, v01, v11};
                for (const auto& tri : cellTriangles(ok[v00], ok[v10], ok[v01], ok[v11]))
                    if (tri[0] < 4)
                        triangle(&attr[corners[tri[0]] * S], &attr[corners[tri[1]] * S], &attr[corners[tri[2]] * S],
                                 0.5);
                continue;
            }
            const auto& cr = weightsFor(K);
            sub.resize(static_cast<std::size_t>(K + 1) * (K + 1) * S);
            for (int b = 0; b <= K; ++b)
                for (int a = 0; a <= K; ++a) {
                    double* o = &sub[(static_cast<std::size_t>(b) * (K + 1) + a) * S];
                    // The Jacobian is the interpolating surface's own, so that each sub-triangle's
                    // density agrees with its flux to second order in its size.
                    if (cubic) {
                        for (std::size_t z = 0; z < J; ++z) o[z] = bicubic(cr[a], cr[b], z);
                        const auto &su = slopes[K][a], &sv = slopes[K][b];
                        o[J] = bicubic(su, cr[b], 0) * bicubic(cr[a], sv, 1) -
                               bicubic(cr[a], sv, 0) * bicubic(su, cr[b], 1);
                    } else {
                        const double u = double(a) / K, v = double(b) / K;
                        for (std::size_t z = 0; z < J; ++z)
                            o[z] = (1 - v) * ((1 - u) * attr[v00 * S + z] + u * attr[v10 * S + z]) +
                                   v * ((1 - u) * attr[v01 * S + z] + u * attr[v11 * S + z]);
                        auto du = [&](std::size_t z) {
                            return (1 - v) * (attr[v10 * S + z] - attr[v00 * S + z]) +
                                   v * (attr[v11 * S + z] - attr[v01 * S + z]);
                        };
                        auto dv = [&](std::size_t z) {
                            return (1 - u) * (attr[v01 * S + z] - attr[v00 * S + z]) +
                                   u * (attr[v11 * S + z] - attr[v10 * S + z]);
                        };
                        o[J] = du(0) * dv(1) - dv(0) * du(1);
                    }
                }
            const double subArea = 0.5 / (double(K) * K);
            for (int b = 0; b < K; ++b)
                for (int a = 0; a < K; ++a) {
                    const double* s00 = &sub[(static_cast<std::size_t>(b) * (K + 1) + a) * S];
                    const double* s10 = s00 + S;
                    const double* s01 = s00 + (K + 1) * S;
                    const double* s11 = s01 + S;
                    triangle(s00, s10, s11, subArea);
                    triangle(s00, s11, s01, subArea);
                }
        }
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
    if (gradients.empty() && (gradient.x != 0.0 || gradient.y != 0.0)) gradients.assign(polys.size(), glm::vec2(0.0f));
    if (!gradients.empty()) gradients.push_back(glm::vec2(gradient));
    polys.push_back(q);
    energy += e;
    ++triangles;
}

} // namespace ff::ghosts
