#include "core/error.h"
#include "core/units.h"
#include "ghosts/mesh_clip.h"
#include "ghosts/shaped_ghosts.h"
#include "ghosts/shaped_mesh.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>

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

// One light's ghost at the two table angles around its field angle.
struct Instance {
    std::size_t light;
    MeshInstance mesh;
    double flux = 0.0;                   ///< summed over the channels
    std::array<double, 3> channelFlux{}; ///< per channel
};

// Catmull-Rom weights of the four samples around a position u in [0, 1] between the middle two.
std::array<double, 4> catmullRom(double u) {
    const double u2 = u * u, u3 = u2 * u;
    return {0.5 * (-u + 2 * u2 - u3), 0.5 * (2 - 5 * u2 + 3 * u3), 0.5 * (u + 4 * u2 - 3 * u3), 0.5 * (-u2 + u3)};
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

    // Per vertex: pixel x, y, weight, then the constraints' values.
    const std::size_t S = 3 + C;
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
            out.add(poly.data(), 3, e);
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
        out.add(poly.data(), clipper.size(), e * share);
    };
    std::vector<std::vector<std::array<double, 4>>> weights(settings.maxSubdivision + 1);
    auto weightsFor = [&](int K) -> const std::vector<std::array<double, 4>>& {
        auto& cr = weights[K];
        if (cr.empty())
            for (int a = 0; a <= K; ++a) cr.push_back(catmullRom(double(a) / K));
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
    const auto half = catmullRom(0.5);
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
                double dev = landing;
                const double sizePx = std::max(
                    {std::abs(attr[v11 * S] - attr[v00 * S]), std::abs(attr[v10 * S] - attr[v01 * S]),
                     std::abs(attr[v11 * S + 1] - attr[v00 * S + 1]), std::abs(attr[v10 * S + 1] - attr[v01 * S + 1])});
                for (std::size_t k = 0; k < C; ++k) {
                    const double a = attr[v00 * S + 3 + k], b = attr[v10 * S + 3 + k], d = attr[v01 * S + 3 + k],
                                 e = attr[v11 * S + 3 + k];
                    const double lo = std::min({a, b, d, e}), hi = std::max({a, b, d, e});
                    if (!(lo < 0.0 && hi >= 0.0)) continue;
                    edge = true;
                    if (cubic) dev = std::max(dev, deviation(3 + k) * sizePx / (hi - lo));
                }
                if (edge && !cubic)
                    K = kEdge;
                else
                    K = std::clamp(static_cast<int>(std::ceil(std::sqrt(dev / in.flatnessPx))), 1,
                                   settings.maxSubdivision);
                // A flat sub-cell carries its mean irradiance; its neighbour's differs by the relative
                // change of the map's Jacobian across it, about 8 dev / (K sizePx) for a map that
                // deviates dev pixels from flat over a cell of sizePx (dev = h^2 x'' / 8, sizePx = h x').
                if (cubic && sizePx > 0.0) {
                    const double bend = 8.0 * landing / sizePx;
                    K = std::max(K, std::clamp(static_cast<int>(std::ceil(bend / in.irradianceStep)), 1,
                                               settings.maxSubdivision));
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
                    if (cubic) {
                        for (std::size_t z = 0; z < S; ++z) o[z] = bicubic(cr[a], cr[b], z);
                    } else {
                        const double u = double(a) / K, v = double(b) / K;
                        for (std::size_t z = 0; z < S; ++z)
                            o[z] = (1 - v) * ((1 - u) * attr[v00 * S + z] + u * attr[v10 * S + z]) +
                                   v * ((1 - u) * attr[v01 * S + z] + u * attr[v11 * S + z]);
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

void ShapedPolygons::add(const glm::dvec2* p, std::size_t n, double e) {
    Poly q{static_cast<std::uint32_t>(vertices.size()), static_cast<std::uint32_t>(n),
           std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(), e};
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec2 v(p[i]);
        vertices.push_back(v);
        q.yMin = std::min(q.yMin, v.y);
        q.yMax = std::max(q.yMax, v.y);
    }
    polys.push_back(q);
    energy += e;
    ++triangles;
}

namespace {

// A gridded instance's mesh is decimated while its cells span at most this many grid cells (the
// bicubic sub-cells place the light within the tolerance inside them) and it keeps this many cells
// per side.
constexpr double kGridCellsPerMeshCell = 2.0;
constexpr int kMinGridCells = 8;
// On the grid, a polygon narrower than this many cells on both axes is splatted bilinearly at its
// vertices' mean: a tent of one cell instead of its exact coverage.
constexpr float kSplatBelowCells = 1.0f;
// Where the bicubic stencil is incomplete, gridded cells cut by an edge get sub-cells of about this
// many grid cells.
constexpr double kGridSubcellCells = 2.0;

} // namespace

double gridErrorSquared(double length, double step) {
    // An edge of unit jump has the spectrum 1 / (2 pi f) across it: beyond the grid's Nyquist
    // frequency 1 / (2 h) it holds 2 Int_{1/2h}^inf df / (4 pi^2 f^2) = h / pi^2 per unit length.
    // The cells' aliases fold about as much back below it: twice that.
    return 2.0 / (std::numbers::pi * std::numbers::pi) * length * step;
}

namespace {

struct Drawn {
    std::vector<std::vector<double>> channel; ///< W frame-sized images
    double energy = 0.0;
    std::size_t triangles = 0;
};

// A chunk of instances at a time: their polygons made in parallel, then drawn, on the CPU into
// bands of rows in parallel, each band in the instances' order (the image does not depend on the
// number of threads), or by the raster given.
Drawn drawInstances(const ShapedTable& table, const std::vector<ShapedLight>& lights,
                    const std::vector<Instance>& instances, const trace::ImageFrame& frame, std::size_t W,
                    const ShapedRenderSettings& settings, PolygonRaster* raster, float splatBelow = 0.0f) {
    Drawn out;
    const int bands = raster ? 0 : std::clamp(frame.height / 64, 1, 16);
    std::vector<trace::ImageFrame> bandFrames;
    std::vector<int> bandRow;
    for (int b = 0; b < bands; ++b) {
        const int r0 = frame.height * b / bands, r1 = frame.height * (b + 1) / bands;
        trace::ImageFrame f = frame;
        f.height = r1 - r0;
        bandFrames.push_back(f);
        bandRow.push_back(r0);
    }
    std::vector<std::vector<trace::CoverageRaster>> rasters(W);
    for (std::size_t w = 0; w < W; ++w)
        for (const auto& f : bandFrames) rasters[w].emplace_back(f);
    if (raster) {
        // A pixel receives at most the energy of all polygons, which the instances' fluxes bound
        // (the drawn energy follows the interpolated flux within a few per cent).
        double bound = 0.0;
        for (const Instance& in : instances) bound += in.flux;
        raster->begin(frame, W, 2.0 * bound + std::numeric_limits<double>::min());
    }
    constexpr std::size_t kChunk = 16;
    std::vector<ShapedPolygons> polys(kChunk * W);
    for (std::size_t i0 = 0; i0 < instances.size(); i0 += kChunk) {
        const std::size_t i1 = std::min(instances.size(), i0 + kChunk);
        tbb::parallel_for(std::size_t(0), (i1 - i0) * W, [&](std::size_t k) {
            const Instance& in = instances[i0 + k / W];
            polys[k] = {};
            const ShapedLight& light = lights[in.light];
            meshPolygons(table, in.mesh, k % W, light.field.azimuthRad, light.flux[k % W], frame, settings, polys[k]);
        });
        if (raster)
            for (std::size_t k = 0; k < (i1 - i0) * W; ++k) raster->draw(k % W, polys[k]);
        else
            tbb::parallel_for(std::size_t(0), W * bands, [&](std::size_t k) {
                const std::size_t w = k / bands, b = k % bands;
                const float r0 = static_cast<float>(bandRow[b]), r1 = r0 + static_cast<float>(bandFrames[b].height);
                trace::RasterStats unused;
                std::array<glm::dvec2, kMaxPolygon> p{};
                for (std::size_t i = i0; i < i1; ++i) {
                    const ShapedPolygons& ps = polys[(i - i0) * W + w];
                    for (const ShapedPolygons::Poly& q : ps.polys) {
                        if (q.yMax < r0 - 1.0f || q.yMin > r1 + 1.0f) continue; // a splat reaches a pixel further
                        for (std::uint32_t v = 0; v < q.count; ++v)
                            p[v] = {ps.vertices[q.first + v].x, ps.vertices[q.first + v].y - r0};
                        if (splatBelow > 0.0 && q.yMax - q.yMin < splatBelow) {
                            double x0 = p[0].x, x1 = x0;
                            glm::dvec2 mean(0.0);
                            for (std::uint32_t v = 0; v < q.count; ++v)
                                mean += p[v], x0 = std::min(x0, p[v].x), x1 = std::max(x1, p[v].x);
                            if (x1 - x0 < splatBelow) {
                                rasters[w][b].point(mean / double(q.count), q.energy, unused);
                                continue;
                            }
                        }
                        rasters[w][b].polygon(std::span(p.data(), q.count), q.energy, unused);
                    }
                }
            });
        for (std::size_t k = 0; k < (i1 - i0) * W; ++k) {
            out.energy += polys[k].energy;
            out.triangles += polys[k].triangles;
        }
    }
    const std::size_t pixels = static_cast<std::size_t>(frame.width) * frame.height;
    if (raster) {
        out.channel = raster->finish();
        if (out.channel.size() != W) throw Error(ErrorKind::Runtime, "the polygon raster drew another frame");
        for (const auto& c : out.channel)
            if (c.size() != pixels) throw Error(ErrorKind::Runtime, "the polygon raster drew another frame");
        return out;
    }
    out.channel.assign(W, std::vector<double>(pixels, 0.0));
    for (std::size_t w = 0; w < W; ++w)
        for (int b = 0; b < bands; ++b) {
            const std::vector<double> band = std::move(rasters[w][b]).release();
            std::copy(band.begin(), band.end(),
                      out.channel[w].begin() + static_cast<std::ptrdiff_t>(bandRow[b]) * frame.width);
        }
    return out;
}

} // namespace

std::vector<char> chooseGridded(const std::vector<std::array<double, 3>>& error2, const std::array<double, 3>& budget,
                                std::array<double, 3>& spent) {
    std::vector<std::pair<double, std::size_t>> order;
    for (std::size_t i = 0; i < error2.size(); ++i) {
        double share = 0.0;
        for (std::size_t c = 0; c < 3; ++c)
            if (error2[i][c] > 0.0)
                share = std::max(share,
                                 budget[c] > 0.0 ? error2[i][c] / budget[c] : std::numeric_limits<double>::infinity());
        order.push_back({share, i});
    }
    std::sort(order.begin(), order.end());
    spent = {};
    std::vector<char> onGrid(error2.size(), 0);
    for (const auto& [share, i] : order) {
        bool fits = std::isfinite(share);
        for (std::size_t c = 0; c < 3 && fits; ++c) fits = error2[i][c] == 0.0 || spent[c] + error2[i][c] <= budget[c];
        if (!fits) break;
        for (std::size_t c = 0; c < 3; ++c) spent[c] += error2[i][c];
        onGrid[i] = 1;
    }
    return onGrid;
}

ShapedRender renderShaped(const ShapedTable& table, const std::vector<ShapedLight>& lights,
                          const trace::ImageFrame& frame, const ShapedRenderSettings& settings, PolygonRaster* raster) {
    ShapedRender out;
    const std::size_t W = std::min<std::size_t>(3, table.wavelengthsNm.size()), G = table.ghosts.size();
    const int A = table.angles();

    // Per light: the interpolation between table angles and the ghosts kept after culling.
    std::vector<Instance> instances;
    for (std::size_t l = 0; l < lights.size(); ++l) {
        const double deg = std::clamp(radToDeg(lights[l].field.angleRad), 0.0, table.maxAngleDeg);
        const double x = A > 1 ? deg / table.angleStep() : 0.0;
        const int a0 = std::clamp(static_cast<int>(std::floor(x)), 0, std::max(0, A - 2));
        const double t = A > 1 ? std::clamp(x - a0, 0.0, 1.0) : 0.0;
        std::vector<std::pair<double, std::size_t>> flux;
        std::vector<std::array<double, 3>> perChannel(G);
        double total = 0.0;
        for (std::size_t g = 0; g < G; ++g) {
            double f = 0.0;
            for (std::size_t w = 0; w < W; ++w) {
                const auto& m = table.ghosts[g].meshes[w];
                perChannel[g][w] = lights[l].flux[w] * ((1.0 - t) * m[a0].flux + t * m[std::min(a0 + 1, A - 1)].flux);
                f += perChannel[g][w];
            }
            flux.push_back({f, g});
            total += f;
        }
        std::sort(flux.begin(), flux.end());
        double dropped = 0.0;
        for (const auto& [f, g] : flux) {
            if (f <= 0.0) continue;
            if (dropped + f <= settings.cullShare * total) {
                dropped += f;
                ++out.culled;
                continue;
            }
            Instance in{l, {g, a0, t, 0.0, 0.0}, f};
            in.channelFlux = perChannel[g];
            instances.push_back(in);
        }
        if (total > 0.0) out.culledShare = std::max(out.culledShare, dropped / total);
    }
    out.drawn = instances.size();

    // Per instance and channel, from its mesh at the lower table angle: the cells' irradiance I
    // (flux per pixel, a cell carrying light where a corner passes every aperture), its squared norm
    // sum I^2 a (a lower bound of the ghost's: Cauchy-Schwarz within each cell), its jumps sum over
    // the cells' shared sides of (I - I')^2 times the side's length (unlit cells and the grid's
    // border count as I' = 0: a uniform ghost gives I^2 times its perimeter), and the perimeter of
    // its outline's box. At the middle wavelength, its mean irradiance over the whole mesh sets its
    // drawing tolerance.
    std::vector<double> irradiance(instances.size(), 0.0);
    std::vector<std::array<double, 3>> norm2(instances.size()), jump2(instances.size()), perimeterPx(instances.size());
    tbb::parallel_for(std::size_t(0), instances.size() * W, [&](std::size_t k) {
        const std::size_t i = k / W, w = k % W;
        const ShapedGhost& gh = table.ghosts[instances[i].mesh.ghost];
        const ShapedMesh& m = gh.meshes[w][instances[i].mesh.a0];
        if (m.data.empty()) return;
        const int n = gh.grid;
        const std::size_t stride = gh.stride();
        const double px2 = frame.pitchMm * frame.pitchMm;
        auto at = [&](int x, int y) { return &m.data[(static_cast<std::size_t>(y) * (n + 1) + x) * stride]; };
        // A vertex passes when it carries light inside every stored aperture and within the iris's
        // circumcircle on every crossing of the stop (its blades cut a little more).
        const std::size_t nA = gh.apertureSteps.size();
        const double iris = table.iris.blades >= 3 ? table.iris.circumradius : table.iris.radius;
        auto passes = [&](const float* v) {
            if (!(v[2] > 0.0f)) return false;
            for (std::size_t a = 0; a < nA; ++a)
                if (!(v[3 + a] >= 0.0f)) return false;
            for (std::size_t c = 0; c < gh.stopCrossings; ++c)
                if (!(std::hypot(v[3 + nA + 2 * c], v[4 + nA + 2 * c]) <= iris)) return false;
            return true;
        };
        std::vector<double> I(static_cast<std::size_t>(n) * n, 0.0), cellArea(I.size(), 0.0);
        double meshArea = 0.0, weights = 0.0;
        double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const float *p = at(x, y), *q = at(x + 1, y), *r = at(x + 1, y + 1), *u = at(x, y + 1);
                const double c = 0.5 * std::abs((r[0] - p[0]) * (u[1] - q[1]) - (r[1] - p[1]) * (u[0] - q[0]));
                if (!std::isfinite(c)) continue;
                meshArea += c;
                if (!(c > 0.0) || !(passes(p) || passes(q) || passes(r) || passes(u))) continue;
                const double weight =
                    0.25 * (std::max(0.0f, p[2]) + std::max(0.0f, q[2]) + std::max(0.0f, r[2]) + std::max(0.0f, u[2]));
                const std::size_t cell = static_cast<std::size_t>(y) * n + x;
                I[cell] = weight / (c / px2);
                cellArea[cell] = c / px2;
                weights += weight;
                for (const float* v : {p, q, r, u})
                    x0 = std::min(x0, double(v[0])), x1 = std::max(x1, double(v[0])), y0 = std::min(y0, double(v[1])),
                    y1 = std::max(y1, double(v[1]));
            }
        if (w == W / 2 && meshArea > 0.0) irradiance[i] = instances[i].flux / (meshArea / px2);
        if (!(weights > 0.0)) return;
        const double scale = instances[i].channelFlux[w] / weights; // flux per unit of weight
        double n2 = 0.0, j2 = 0.0;
        auto side = [&](const float* a, const float* b, double fallback) {
            const double len = std::hypot(double(a[0]) - b[0], double(a[1]) - b[1]) / frame.pitchMm;
            return std::isfinite(len) ? len : fallback;
        };
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const std::size_t cell = static_cast<std::size_t>(y) * n + x;
                const double here = scale * I[cell], fallback = std::sqrt(cellArea[cell]);
                n2 += here * here * cellArea[cell];
                // Its right and lower sides against the neighbour (or the border); its left and upper
                // sides against the border.
                const double right = x + 1 < n ? scale * I[cell + 1] : 0.0;
                const double below = y + 1 < n ? scale * I[cell + n] : 0.0;
                if (here > 0.0 || right > 0.0)
                    j2 += (here - right) * (here - right) * side(at(x + 1, y), at(x + 1, y + 1), fallback);
                if (here > 0.0 || below > 0.0)
                    j2 += (here - below) * (here - below) * side(at(x, y + 1), at(x + 1, y + 1), fallback);
                if (x == 0 && here > 0.0) j2 += here * here * side(at(0, y), at(0, y + 1), fallback);
                if (y == 0 && here > 0.0) j2 += here * here * side(at(x, 0), at(x + 1, 0), fallback);
            }
        norm2[i][w] = n2;
        jump2[i][w] = j2;
        perimeterPx[i][w] = x1 >= x0 ? 2.0 * (x1 - x0 + y1 - y0) / frame.pitchMm : 0.0;
    });
    // Each instance's tolerance: settings.flatnessPx for the instance of highest mean irradiance,
    // growing in inverse proportion to the irradiance up to settings.maxFlatnessPx: a ghost's share
    // of the image's squared error is its irradiance squared times the area its misplaced edges sweep.
    const double top = irradiance.empty() ? 0.0 : *std::max_element(irradiance.begin(), irradiance.end());
    for (std::size_t i = 0; i < instances.size(); ++i) {
        const double dim = irradiance[i] > 0.0 ? top / irradiance[i] : std::numeric_limits<double>::infinity();
        instances[i].mesh.flatnessPx = std::min(settings.maxFlatnessPx, settings.flatnessPx * dim);
        instances[i].mesh.irradianceStep = settings.irradianceStep * dim;
    }

    // The split. Per channel c, instance i has ||g||^2 >= norm2 and, on the grid, the squared error
    // e^2 = gridErrorSquared(1, h) x jump2 (the edges' spectrum beyond the grid's Nyquist frequency,
    // each side weighted by its jump squared). Taken in increasing order of their largest share of
    // a channel's budget, instances go onto the grid while every channel keeps
    // sum e^2 <= gridError^2 sum ||g||^2 (errors of different ghosts added as uncorrelated).
    std::vector<Instance> direct, gridded;
    const auto& grid = settings.grid;
    if (settings.gridError > 0.0 && grid.step > 0 && grid.width > 0 && grid.height > 0) {
        std::array<double, 3> budget{};
        std::vector<std::array<double, 3>> err(instances.size());
        for (std::size_t i = 0; i < instances.size(); ++i)
            for (std::size_t c = 0; c < W; ++c) {
                budget[c] += norm2[i][c];
                err[i][c] = jump2[i][c] * gridErrorSquared(1.0, grid.step);
            }
        for (double& b : budget) b *= settings.gridError * settings.gridError;
        std::array<double, 3> spent{};
        const std::vector<char> onGrid = chooseGridded(err, budget, spent);
        for (std::size_t c = 0; c < W; ++c)
            if (budget[c] > 0.0)
                out.gridErrorEstimate =
                    std::max(out.gridErrorEstimate, std::sqrt(spent[c] / budget[c]) * settings.gridError);
        for (std::size_t i = 0; i < instances.size(); ++i) {
            if (!onGrid[i]) {
                direct.push_back(instances[i]);
                continue;
            }
            // On the grid: a tolerance in grid cells, the mesh decimated while its cells (a quarter
            // of the outline's box perimeter over the grid) span at most kGridCellsPerMeshCell.
            Instance in = instances[i];
            const ShapedGhost& gh = table.ghosts[in.mesh.ghost];
            const double cellPx = 0.25 * *std::max_element(perimeterPx[i].begin(), perimeterPx[i].end()) / gh.grid;
            in.mesh.flatnessPx = settings.gridFlatness;
            in.mesh.irradianceStep = std::numeric_limits<double>::infinity();
            in.mesh.decimation = 1;
            for (int d = 2; gh.grid / d >= kMinGridCells; ++d)
                if (gh.grid % d == 0 && d * cellPx <= kGridCellsPerMeshCell * grid.step) in.mesh.decimation = d;
            gridded.push_back(in);
        }
    } else {
        direct = std::move(instances);
    }
    out.gridded = gridded.size();

    Drawn drawn = drawInstances(table, lights, direct, frame, W, settings, raster);
    double energy = drawn.energy;
    out.triangles = drawn.triangles;
    const std::size_t pixels = static_cast<std::size_t>(frame.width) * frame.height;
    for (std::size_t w = 0; w < 3; ++w) {
        out.channel[w] = w < W ? std::move(drawn.channel[w]) : std::vector<double>(pixels, 0.0);
        for (double v : out.channel[w]) out.deposited += v;
    }
    if (!gridded.empty()) {
        // The grid as a frame of its own: cells of step pixels, placed on the frame's pixels.
        trace::ImageFrame gf{grid.width, grid.height, frame.pitchMm * grid.step};
        const glm::dvec2 centre =
            frame.pixelToSensor(grid.x0 + 0.5 * grid.width * grid.step, grid.y0 + 0.5 * grid.height * grid.step);
        gf.centreXMm = centre.x;
        gf.centreYMm = centre.y;
        ShapedRenderSettings onCells = settings;
        onCells.subcellPx = kGridSubcellCells;
        Drawn onGrid = drawInstances(table, lights, gridded, gf, W, onCells, nullptr, kSplatBelowCells);
        energy += onGrid.energy;
        out.gridTriangles = onGrid.triangles;
        for (std::size_t w = 0; w < 3; ++w) {
            out.grid[w] = w < W ? std::move(onGrid.channel[w])
                                : std::vector<double>(static_cast<std::size_t>(grid.width) * grid.height, 0.0);
            // What the grid holds inside the frame reaches it (the series keeps each cell's flux).
            for (int j = 0; j < grid.height; ++j)
                for (int i = 0; i < grid.width; ++i) {
                    const double x0 = grid.x0 + i * grid.step, y0 = grid.y0 + j * grid.step;
                    const double cx = std::clamp(std::min(x0 + grid.step, double(frame.width)) - std::max(x0, 0.0), 0.0,
                                                 double(grid.step)),
                                 cy = std::clamp(std::min(y0 + grid.step, double(frame.height)) - std::max(y0, 0.0),
                                                 0.0, double(grid.step));
                    out.deposited += out.grid[w][static_cast<std::size_t>(j) * grid.width + i] * cx * cy /
                                     (double(grid.step) * grid.step);
                }
        }
    }
    out.offImage = std::max(0.0, energy - out.deposited);
    return out;
}

} // namespace ff::ghosts
