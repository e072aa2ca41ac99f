#include "ghosts/shaped_ghosts.h"

#include "core/error.h"
#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/sequential_tracer.h"
#include "trace/traced_flare.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>

namespace ff::ghosts {

namespace {

constexpr int kCoarse = 48;     // points per side of the pass that finds where a ghost's light is
constexpr int kMinGrid = 16;    // the coarsest grid a ghost's mesh gets
constexpr int kDirectGrid = 96; // cells per side of the direct path's mesh (its flux normalises)
constexpr std::size_t kMaxConstraints = 40;
constexpr std::size_t kMaxPolygon = kMaxConstraints + 3;

double defaultMaxAngle(const optics::Lens& lens, std::pair<double, double> size, double sensorZ) {
    const double halfDiagonal = 0.5 * std::hypot(size.first, size.second) * 1.05;
    try {
        return radToDeg(trace::fieldForSensorPoint(lens, sensorZ, 0.0, halfDiagonal).angleRad);
    } catch (const Error&) {
        return std::min(80.0, radToDeg(std::atan(halfDiagonal / std::abs(optics::paraxialEfl(lens, lines::d)))));
    }
}

// A rectangle of the entrance-pupil plane, mm.
struct Rect {
    double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
    bool empty() const { return !(x1 > x0 && y1 > y0); }
};

// Rays of a field through the pupil-plane points (x, y), started in front of the lens.
struct RayMaker {
    const trace::PupilFrame& pupil;
    glm::dvec3 dir;
    double back;
    RayMaker(const trace::PupilFrame& p, const trace::Field& f)
        : pupil(p), dir(trace::fieldDirection(f, p.eflSign)), back((p.z - p.startZ) / dir.z) {}
    optics::Ray operator()(double x, double y) const { return {glm::dvec3(x, y, pupil.z) - back * dir, dir}; }
};

// A path's open trace over the (n+1)^2 corners of a rectangle's n x n cells: per vertex its landing
// point, weight and every step's margin and hit point (NaN where the trace ended).
struct OpenMesh {
    int n = 0;
    std::size_t steps = 0;
    std::vector<char> ok;
    std::vector<glm::dvec2> land;
    std::vector<double> weight, margins; // margins [vertex * steps + step]
    std::vector<glm::dvec3> points;      // [vertex * steps + step]
};

OpenMesh traceMesh(const trace::LensAtWavelength& L, const std::vector<trace::PathStep>& steps, const RayMaker& rays,
                   const Rect& r, int n) {
    OpenMesh m;
    m.n = n;
    m.steps = steps.size();
    const std::size_t V = static_cast<std::size_t>(n + 1) * (n + 1);
    m.ok.assign(V, 0);
    m.land.assign(V, glm::dvec2(0.0));
    m.weight.assign(V, 0.0);
    m.margins.assign(V * m.steps, 0.0);
    m.points.assign(V * m.steps, glm::dvec3(0.0));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const std::size_t v = static_cast<std::size_t>(j) * (n + 1) + i;
            const double x = r.x0 + (r.x1 - r.x0) * i / n, y = r.y0 + (r.y1 - r.y0) * j / n;
            const trace::SequentialResult s = trace::traceSequential(L, steps, rays(x, y), trace::Weighting::Fresnel,
                                                                     &m.margins[v * m.steps], &m.points[v * m.steps]);
            if (s.status != optics::RayStatus::Ok || !std::isfinite(s.ray.origin.x) || !std::isfinite(s.ray.origin.y))
                continue;
            m.ok[v] = 1;
            m.land[v] = {s.ray.origin.x, s.ray.origin.y};
            m.weight[v] = s.weight;
        }
    return m;
}

// A triangle with per-vertex constraint values (linear across it), clipped to where all are >= 0.
// Polygon vertices are barycentric coordinates. Returns the lit share of the triangle's area.
class TriangleClipper {
  public:
    // c[k][i]: constraint k at vertex i. The clipped polygon is left in poly() (barycentrics).
    double clip(const std::array<double, 3>* c, std::size_t constraints) {
        count_ = 3;
        a_[0] = {1, 0, 0};
        a_[1] = {0, 1, 0};
        a_[2] = {0, 0, 1};
        for (std::size_t k = 0; k < constraints && count_ > 0; ++k) {
            const auto& ck = c[k];
            std::size_t m = 0;
            for (std::size_t p = 0; p < count_; ++p) {
                const glm::dvec3& A = a_[p];
                const glm::dvec3& B = a_[(p + 1) % count_];
                const double va = A.x * ck[0] + A.y * ck[1] + A.z * ck[2];
                const double vb = B.x * ck[0] + B.y * ck[1] + B.z * ck[2];
                if (va >= 0.0 && m < kMaxPolygon) b_[m++] = A;
                if ((va >= 0.0) != (vb >= 0.0) && m < kMaxPolygon) b_[m++] = A + (B - A) * (va / (va - vb));
            }
            std::swap(a_, b_);
            count_ = m;
        }
        if (count_ < 3) return 0.0;
        // Area in the (b1, b2) plane relative to the whole triangle's 1/2.
        double area = 0.0;
        for (std::size_t p = 0; p < count_; ++p) {
            const glm::dvec3& A = a_[p];
            const glm::dvec3& B = a_[(p + 1) % count_];
            area += A.y * B.z - B.y * A.z;
        }
        return std::clamp(std::abs(area), 0.0, 1.0);
    }
    std::size_t size() const { return count_; }
    const glm::dvec3& operator[](std::size_t p) const { return a_[p]; }

  private:
    std::array<glm::dvec3, kMaxPolygon> a_, b_;
    std::size_t count_ = 0;
};

// The two triangles of a grid cell as corner indices (0: (i, j), 1: (i+1, j), 2: (i, j+1), 3: (i+1,
// j+1)) whose corners are all traced; {4, 4, 4} stands for none. The cell is split along the
// diagonal that keeps a triangle when one corner is lost.
std::array<std::array<int, 3>, 2> cellTriangles(bool c0, bool c1, bool c2, bool c3) {
    constexpr std::array<int, 3> none{4, 4, 4};
    if (c0 && c3) return {c1 ? std::array{0, 1, 3} : none, c2 ? std::array{0, 3, 2} : none};
    return {c0 && c1 && c2 ? std::array{0, 1, 2} : none, c1 && c2 && c3 ? std::array{1, 3, 2} : none};
}

// The flux of a mesh: the weight integrated over the lit part of every traced triangle of every
// cell (cellTriangles; in cells, the caller scales by the cell's area).
template <typename Constraints>
double meshFlux(int n, const std::vector<char>& ok, const std::vector<double>& weight, std::size_t constraints,
                Constraints&& value) {
    TriangleClipper clipper;
    std::vector<std::array<double, 3>> c(constraints);
    double sum = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t v00 = static_cast<std::size_t>(j) * (n + 1) + i, v10 = v00 + 1, v01 = v00 + n + 1,
                              v11 = v01 + 1;
            const std::array<std::size_t, 4> corners{v00, v10, v01, v11};
            for (const auto& tri : cellTriangles(ok[v00], ok[v10], ok[v01], ok[v11])) {
                if (tri[0] >= 4) continue;
                const std::array<std::size_t, 3> t{corners[tri[0]], corners[tri[1]], corners[tri[2]]};
                for (std::size_t k = 0; k < constraints; ++k)
                    for (int q = 0; q < 3; ++q) c[k][q] = value(t[q], k);
                const double share = clipper.clip(c.data(), constraints);
                sum += share * 0.5 * (weight[t[0]] + weight[t[1]] + weight[t[2]]) / 3.0;
            }
        }
    return sum;
}

// The margins of an open mesh's vertex as constraints: every step's margin, NaN read as far outside.
auto marginsOf(const OpenMesh& m) {
    return [&m](std::size_t v, std::size_t k) {
        const double x = m.margins[v * m.steps + k];
        return std::isnan(x) ? -1e30 : std::min(x, 1e30);
    };
}

// Where a path's light passes at one field, from a kCoarse x kCoarse open trace over everything that
// could enter the front surface: the box of the points whose trace passes every aperture, one pass
// spacing wider on every side (clamped to the pass's square); the light's flux (pupil mm^2 x weight)
// and the area of the box its lit points land in (sensor mm^2).
struct Probe {
    Rect rect;
    double flux = 0.0, landingArea = 0.0;
};

Probe probe(const trace::LensAtWavelength& L, const std::vector<trace::PathStep>& steps, const trace::PupilFrame& pupil,
            const trace::Field& field) {
    const double h = trace::searchHalfSize(pupil, field);
    const RayMaker rays(pupil, field);
    const OpenMesh m = traceMesh(L, steps, rays, {-h, -h, h, h}, kCoarse);
    constexpr double inf = std::numeric_limits<double>::infinity();
    Rect box{inf, inf, -inf, -inf}, land{inf, inf, -inf, -inf};
    const double cell = 2.0 * h / kCoarse;
    for (int j = 0; j <= kCoarse; ++j)
        for (int i = 0; i <= kCoarse; ++i) {
            const std::size_t v = static_cast<std::size_t>(j) * (kCoarse + 1) + i;
            if (!m.ok[v]) continue;
            bool lit = true;
            for (std::size_t k = 0; k < m.steps && lit; ++k) lit = m.margins[v * m.steps + k] >= 0.0;
            if (!lit) continue;
            const double x = -h + cell * i, y = -h + cell * j;
            box = {std::min(box.x0, x - cell), std::min(box.y0, y - cell), std::max(box.x1, x + cell),
                   std::max(box.y1, y + cell)};
            land = {std::min(land.x0, m.land[v].x), std::min(land.y0, m.land[v].y), std::max(land.x1, m.land[v].x),
                    std::max(land.y1, m.land[v].y)};
        }
    Probe out;
    if (!(box.x1 > box.x0)) return out;
    out.rect = {std::max(box.x0, -h), std::max(box.y0, -h), std::min(box.x1, h), std::min(box.y1, h)};
    out.flux = cell * cell * meshFlux(kCoarse, m.ok, m.weight, m.steps, marginsOf(m));
    out.landingArea = (land.x1 - land.x0) * (land.y1 - land.y0);
    return out;
}

// The direct image's flux at one field and wavelength (pupil mm^2 x weight), its apertures' edges
// clipped as the ghosts' are.
double directFlux(const trace::LensAtWavelength& L, const std::vector<trace::PathStep>& steps,
                  const trace::PupilFrame& pupil, const trace::Field& field, std::size_t& rays) {
    const Rect r = probe(L, steps, pupil, field).rect;
    rays += (kCoarse + 1) * (kCoarse + 1);
    if (r.empty()) return 0.0;
    const OpenMesh m = traceMesh(L, steps, RayMaker(pupil, field), r, kDirectGrid);
    rays += m.ok.size();
    const double cellArea = (r.x1 - r.x0) * (r.y1 - r.y0) / (double(kDirectGrid) * kDirectGrid);
    return cellArea * meshFlux(kDirectGrid, m.ok, m.weight, m.steps, marginsOf(m));
}

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

} // namespace

std::size_t ShapedTable::bytes() const {
    std::size_t b = 0;
    for (const ShapedGhost& g : ghosts)
        for (const auto& w : g.meshes)
            for (const ShapedMesh& m : w) b += m.data.size() * sizeof(float);
    return b;
}

ShapedTable buildShapedTable(const optics::Lens& lensIn, const ShapedSettings& s,
                             const std::function<void(std::size_t, std::size_t)>& progress) {
    const auto start = std::chrono::steady_clock::now();
    if (s.grid < 2 || s.grid > 512)
        throw Error(ErrorKind::Usage, "the shaped ghosts' grid must be 2 to 512 cells per side");
    if (s.angles < 2 || s.angles > 1024) throw Error(ErrorKind::Usage, "the shaped ghosts need 2 to 1024 field angles");
    const optics::Lens lens = trace::withCoating(lensIn, s.coating);
    const double sensorZ = trace::sensorPlaneZ(lens, s.sensor);
    ShapedTable table;
    table.lensName = lens.name;
    table.lensHash = lens.contentHash;
    table.wavelengthsNm = s.wavelengthsNm;
    table.maxAngleDeg =
        s.maxAngleDeg > 0.0
            ? s.maxAngleDeg
            : defaultMaxAngle(lens, s.sensorSizeMm.value_or(lens.sensorMm.value_or(std::make_pair(36.0, 24.0))),
                              sensorZ);
    table.iris = trace::LensAtWavelength(lens, lines::d, sensorZ).iris;
    const trace::PupilFrame pupil = trace::pupilFrame(lens);
    const auto pairs = trace::enumerateGhosts(lens);
    table.ghostCount = pairs.size();
    std::vector<trace::LensAtWavelength> Ls;
    for (double l : s.wavelengthsNm) Ls.emplace_back(lens, l, sensorZ);
    const std::size_t W = Ls.size(), A = static_cast<std::size_t>(s.angles), G = pairs.size();
    auto fieldAt = [&](std::size_t a) {
        return trace::Field{degToRad(table.maxAngleDeg * double(a) / double(A - 1)), 0.0};
    };

    // The direct image's flux per wavelength and angle.
    const auto directSteps = trace::pathSteps(lens, std::nullopt);
    std::vector<double> direct(W * A, 0.0);
    std::vector<std::size_t> rays(G + W * A, 0);
    tbb::parallel_for(std::size_t(0), W * A, [&](std::size_t t) {
        direct[t] = directFlux(Ls[t / A], directSteps, pupil, fieldAt(t % A), rays[G + t]);
    });

    // Where each ghost's light is at each angle, probed at the middle wavelength. A ghost's meshes
    // all cover the rectangle over its light at every angle: a vertex is then the same pupil point at
    // every angle, and interpolating between angles follows that ray (rectangles fitted per angle
    // move in steps of the probe's spacing, and a vertex interpolated between two of them mixes two
    // rays: the double Gauss at (60, 40) of 960 x 540 was 0.17 off its trace with them, 0.09 with one).
    const std::size_t mid = W / 2;
    std::vector<Probe> probes(G * A);
    tbb::parallel_for(std::size_t(0), G * A, [&](std::size_t t) {
        probes[t] = probe(Ls[mid], trace::pathSteps(lens, pairs[t / A]), pupil, fieldAt(t % A));
    });
    std::vector<double> importance(G, 0.0);
    std::vector<std::vector<Rect>> rects(G, std::vector<Rect>(A));
    const auto sensor = s.sensorSizeMm.value_or(lens.sensorMm.value_or(std::make_pair(36.0, 24.0)));
    // Below ten pixels of a 1000-pixel-wide frame across, a ghost's inner structure is not seen.
    const double minArea = std::pow(1e-2 * sensor.first, 2);
    for (std::size_t g = 0; g < G; ++g) {
        std::vector<std::size_t> lit;
        for (std::size_t a = 0; a < A; ++a) {
            const Probe& p = probes[g * A + a];
            if (p.rect.empty()) continue;
            lit.push_back(a);
            const double f = direct[mid * A + a] > 0.0 ? p.flux / direct[mid * A + a] : 0.0;
            importance[g] += f * f / std::max(p.landingArea, minArea) / double(A);
        }
        if (lit.empty()) continue;
        Rect u = probes[g * A + lit.front()].rect;
        for (std::size_t a : lit) {
            const Rect& r = probes[g * A + a].rect;
            u = {std::min(u.x0, r.x0), std::min(u.y0, r.y0), std::max(u.x1, r.x1), std::max(u.y1, r.y1)};
        }
        rects[g].assign(A, u);
    }
    const std::size_t rayCount = probes.size() * (kCoarse + 1) * (kCoarse + 1);
    probes.clear();
    // Each ghost's grid: its share of the image's squared norm is about flux^2 / area (importance),
    // and the mesh's error about that over the grid squared; the total error for a given number of
    // rays is least with grids growing as importance^(1/4).
    const double top = G ? *std::max_element(importance.begin(), importance.end()) : 0.0;
    std::vector<int> grids(G, 0);
    for (std::size_t g = 0; g < G; ++g) {
        if (!(importance[g] > 0.0)) continue;
        const double n = s.grid * std::pow(importance[g] / top, 0.25);
        grids[g] = std::clamp(8 * static_cast<int>(std::lround(n / 8.0)), std::min(s.grid, kMinGrid), s.grid);
    }

    // Each ghost's meshes; then the apertures that cut it somewhere are kept.
    std::vector<ShapedGhost> ghosts(G);
    std::vector<double> peak(G, 0.0);
    std::atomic<std::size_t> done = 0;
    tbb::parallel_for(std::size_t(0), G, [&](std::size_t g) {
        ShapedGhost& out = ghosts[g];
        out.pair = pairs[g];
        const int n = grids[g];
        if (n == 0) return;
        out.grid = n;
        const auto steps = trace::pathSteps(lens, pairs[g]);
        std::vector<std::size_t> stopSteps;
        for (std::size_t k = 0; k < steps.size(); ++k)
            if (steps[k].surface == Ls[0].stop) stopSteps.push_back(k);
        out.stopCrossings = stopSteps.size();
        // Every vertex as x, y, weight, every step's margin (NaN: none), then the stop hits.
        const std::size_t K = steps.size(), full = 3 + K + 2 * stopSteps.size();
        std::vector<char> cuts(K, 0);
        out.meshes.assign(W, std::vector<ShapedMesh>(A));
        for (std::size_t w = 0; w < W; ++w)
            for (std::size_t a = 0; a < A; ++a) {
                const Rect& r = rects[g][a];
                OpenMesh m = traceMesh(Ls[w], steps, RayMaker(pupil, fieldAt(a)), r, n);
                rays[g] += m.ok.size();
                const double cellArea = (r.x1 - r.x0) * (r.y1 - r.y0) / (double(n) * n);
                const double scale = direct[w * A + a] > 0.0 ? cellArea / direct[w * A + a] : 0.0;
                for (double& x : m.weight) x *= scale;
                out.meshes[w][a].flux = meshFlux(n, m.ok, m.weight, m.steps, marginsOf(m));
                peak[g] = std::max(peak[g], out.meshes[w][a].flux);
                std::vector<float>& d = out.meshes[w][a].data;
                d.assign(m.ok.size() * full, 0.0f);
                for (std::size_t v = 0; v < m.ok.size(); ++v) {
                    float* p = &d[v * full];
                    if (!m.ok[v]) {
                        p[0] = std::numeric_limits<float>::quiet_NaN();
                        continue;
                    }
                    p[0] = static_cast<float>(m.land[v].x);
                    p[1] = static_cast<float>(m.land[v].y);
                    p[2] = static_cast<float>(m.weight[v]);
                    for (std::size_t k = 0; k < K; ++k) {
                        const double x = m.margins[v * K + k];
                        p[3 + k] = static_cast<float>(std::clamp(x, -1e30, 1e30));
                        if (x < 0.0 && steps[k].surface != Ls[0].stop) cuts[k] = 1;
                    }
                    std::size_t q = 3 + K;
                    for (std::size_t k : stopSteps) {
                        p[q++] = static_cast<float>(m.points[v * K + k].x);
                        p[q++] = static_cast<float>(m.points[v * K + k].y);
                    }
                }
            }
        for (std::size_t k = 0; k < K; ++k)
            if (cuts[k]) out.apertureSteps.push_back(k);
        // Keep x, y, weight, the cutting apertures' margins and the stop hits.
        const std::size_t stride = out.stride();
        for (auto& byAngle : out.meshes)
            for (ShapedMesh& mesh : byAngle) {
                std::vector<float> d(mesh.data.size() / full * stride);
                for (std::size_t v = 0; v < mesh.data.size() / full; ++v) {
                    const float* p = &mesh.data[v * full];
                    float* q = &d[v * stride];
                    q[0] = p[0], q[1] = p[1], q[2] = p[2];
                    std::size_t c = 3;
                    for (std::size_t k : out.apertureSteps) q[c++] = p[3 + k];
                    for (std::size_t k = 0; k < 2 * stopSteps.size(); ++k) q[c++] = p[3 + K + k];
                }
                mesh.data = std::move(d);
            }
        if (progress) progress(++done, G);
    });
    const double strongest = G ? *std::max_element(peak.begin(), peak.end()) : 0.0;
    for (std::size_t g = 0; g < G; ++g)
        if (peak[g] > 0.0 && peak[g] >= s.storeFraction * strongest) table.ghosts.push_back(std::move(ghosts[g]));
    table.rays = rayCount + std::accumulate(rays.begin(), rays.end(), std::size_t(0));
    table.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return table;
}

namespace {

// One light's ghost at the two table angles around its field angle.
struct Instance {
    std::size_t light, ghost;
    int a0;
    double t;
    double flux = 0.0;       ///< summed over the channels
    double flatnessPx = 0.0; ///< the subdivision's tolerance for this instance (ShapedRenderSettings)
};

// Cuts one instance's mesh at one wavelength into clipped polygons (pixels; shaped_ghosts.h).
void meshPolygons(const ShapedTable& table, const Instance& in, std::size_t w, const ShapedLight& light,
                  const trace::ImageFrame& frame, const ShapedRenderSettings& settings, ShapedPolygons& out) {
    const ShapedGhost& gh = table.ghosts[in.ghost];
    const int A = table.angles();
    const ShapedMesh& m0 = gh.meshes[w][in.a0];
    const ShapedMesh& m1 = gh.meshes[w][std::min(in.a0 + 1, A - 1)];
    const std::size_t stride = gh.stride(), nA = gh.apertureSteps.size();
    const int n = gh.grid;
    const std::size_t V = static_cast<std::size_t>(n + 1) * (n + 1);
    const double cs = std::cos(light.field.azimuthRad), sn = std::sin(light.field.azimuthRad);
    const IrisEdges iris(table.iris, -light.field.azimuthRad);
    const std::size_t C = std::min(kMaxConstraints, nA + gh.stopCrossings * iris.count());

    // Per vertex: pixel x, y, weight, then the constraints' values.
    const std::size_t S = 3 + C;
    std::vector<double> attr(V * S, 0.0);
    std::vector<char> ok(V, 0);
    double xMin = std::numeric_limits<double>::infinity(), xMax = -xMin, yMin = xMin, yMax = -xMin;
    for (std::size_t v = 0; v < V; ++v) {
        const float* p = &m0.data[v * stride];
        const float* q = &m1.data[v * stride];
        // A ray lost at one of the two angles is taken from the other up to the middle between
        // them, and lost beyond it.
        double t = in.t;
        if (std::isnan(p[0]) || std::isnan(q[0])) {
            if (std::isnan(p[0]) == std::isnan(q[0]) || std::isnan(p[0]) == (t < 0.5)) continue;
            t = std::isnan(p[0]) ? 1.0 : 0.0;
        }
        auto lerp = [t](float a, float b) {
            return t == 0.0 ? double(a) : t == 1.0 ? double(b) : (1.0 - t) * a + t * b;
        };
        const double x = lerp(p[0], q[0]), y = lerp(p[1], q[1]);
        const glm::dvec2 px = frame.sensorToPixel(cs * x - sn * y, sn * x + cs * y);
        double* o = &attr[v * S];
        o[0] = px.x;
        o[1] = px.y;
        o[2] = lerp(p[2], q[2]);
        ok[v] = 1;
        std::size_t k = 0;
        for (; k < nA && k < C; ++k) o[3 + k] = lerp(p[3 + k], q[3 + k]);
        for (std::size_t s = 0; s < gh.stopCrossings; ++s) {
            const double sx = lerp(p[3 + nA + 2 * s], q[3 + nA + 2 * s]);
            const double sy = lerp(p[4 + nA + 2 * s], q[4 + nA + 2 * s]);
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
    const double flux = light.flux[w];
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
            return;
        }
        const double share = clipper.clip(c.data(), active);
        if (share <= 0.0) return;
        for (std::size_t q = 0; q < clipper.size(); ++q) {
            const glm::dvec3& b = clipper[q];
            poly[q] = {b.x * P[0] + b.y * Q[0] + b.z * R[0], b.x * P[1] + b.y * Q[1] + b.z * R[1]};
        }
        out.add(poly.data(), clipper.size(), e * share);
    };
    // Catmull-Rom weights of the four grid points around a position u in [0, 1] of a cell.
    auto catmullRom = [](double u) {
        const double u2 = u * u, u3 = u2 * u;
        return std::array<double, 4>{0.5 * (-u + 2 * u2 - u3), 0.5 * (2 - 5 * u2 + 3 * u3), 0.5 * (u + 4 * u2 - 3 * u3),
                                     0.5 * (-u2 + u3)};
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
            if (all) {
                // Deviation of the bicubic surface from the flat cell at its centre, in pixels: of
                // the landing point, and of where a cutting aperture's edge (a constraint's zero)
                // crosses the cell (the constraint's deviation over its gradient across the cell).
                auto deviation = [&](std::size_t z) {
                    const double flat =
                        0.25 * (attr[v00 * S + z] + attr[v10 * S + z] + attr[v01 * S + z] + attr[v11 * S + z]);
                    return std::abs(bicubic(half, half, z) - flat);
                };
                bool edge = false;
                double dev = cubic ? std::max(deviation(0), deviation(1)) : 0.0;
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

} // namespace

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
        double total = 0.0;
        for (std::size_t g = 0; g < G; ++g) {
            double f = 0.0;
            for (std::size_t w = 0; w < W; ++w) {
                const auto& m = table.ghosts[g].meshes[w];
                f += lights[l].flux[w] * ((1.0 - t) * m[a0].flux + t * m[std::min(a0 + 1, A - 1)].flux);
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
            instances.push_back({l, g, a0, t, f});
        }
        if (total > 0.0) out.culledShare = std::max(out.culledShare, dropped / total);
    }
    out.drawn = instances.size();

    // Each instance's tolerance: settings.flatnessPx for the instance of highest mean irradiance
    // (flux over the area its mesh spans), growing in inverse proportion to the irradiance up to
    // settings.maxFlatnessPx: a ghost's share of the image's squared error is its irradiance
    // squared times the area its misplaced edges sweep.
    {
        std::vector<double> irradiance(instances.size(), 0.0);
        tbb::parallel_for(std::size_t(0), instances.size(), [&](std::size_t i) {
            const ShapedGhost& gh = table.ghosts[instances[i].ghost];
            const ShapedMesh& m = gh.meshes[W / 2][instances[i].a0];
            const int n = gh.grid;
            const std::size_t stride = gh.stride();
            auto at = [&](int x, int y) { return &m.data[(static_cast<std::size_t>(y) * (n + 1) + x) * stride]; };
            double area = 0.0;
            if (!m.data.empty())
                for (int y = 0; y < n; ++y)
                    for (int x = 0; x < n; ++x) {
                        const float *p = at(x, y), *q = at(x + 1, y), *r = at(x + 1, y + 1), *u = at(x, y + 1);
                        const double c = 0.5 * std::abs((r[0] - p[0]) * (u[1] - q[1]) - (r[1] - p[1]) * (u[0] - q[0]));
                        if (std::isfinite(c)) area += c;
                    }
            area /= frame.pitchMm * frame.pitchMm;
            irradiance[i] = area > 0.0 ? instances[i].flux / area : 0.0;
        });
        const double top = irradiance.empty() ? 0.0 : *std::max_element(irradiance.begin(), irradiance.end());
        for (std::size_t i = 0; i < instances.size(); ++i)
            instances[i].flatnessPx = irradiance[i] > 0.0
                                          ? std::min(settings.maxFlatnessPx, settings.flatnessPx * top / irradiance[i])
                                          : settings.maxFlatnessPx;
    }

    // A chunk of instances at a time: their polygons made in parallel, then drawn, on the CPU into
    // bands of rows in parallel, each band in the instances' order (the image does not depend on
    // the number of threads), or by the raster given.
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
    double energy = 0.0;
    std::vector<ShapedPolygons> polys(kChunk * W);
    for (std::size_t i0 = 0; i0 < instances.size(); i0 += kChunk) {
        const std::size_t i1 = std::min(instances.size(), i0 + kChunk);
        tbb::parallel_for(std::size_t(0), (i1 - i0) * W, [&](std::size_t k) {
            const Instance& in = instances[i0 + k / W];
            polys[k] = {};
            meshPolygons(table, in, k % W, lights[in.light], frame, settings, polys[k]);
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
                        rasters[w][b].polygon(std::span(p.data(), q.count), q.energy, unused);
                    }
                }
            });
        for (std::size_t k = 0; k < (i1 - i0) * W; ++k) {
            energy += polys[k].energy;
            out.triangles += polys[k].triangles;
        }
    }
    const std::size_t pixels = static_cast<std::size_t>(frame.width) * frame.height;
    std::vector<std::vector<double>> drawn;
    if (raster) drawn = raster->finish();
    for (std::size_t w = 0; w < 3; ++w) {
        out.channel[w].assign(pixels, 0.0);
        if (w >= W) continue;
        if (raster) {
            out.channel[w] = std::move(drawn.at(w));
            if (out.channel[w].size() != pixels)
                throw Error(ErrorKind::Runtime, "the polygon raster drew another frame");
        }
        for (int b = 0; b < bands; ++b) {
            const std::vector<double> band = std::move(rasters[w][b]).release();
            std::copy(band.begin(), band.end(),
                      out.channel[w].begin() + static_cast<std::ptrdiff_t>(bandRow[b]) * frame.width);
        }
        for (double v : out.channel[w]) out.deposited += v;
    }
    out.offImage = std::max(0.0, energy - out.deposited);
    return out;
}

} // namespace ff::ghosts
