#include "ghosts/shaped_ghosts.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "ghosts/mesh_clip.h"
#include "ghosts/tensor_polynomial.h"
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

constexpr int kCoarse = 48; // points per side of the pass that finds where a ghost's light is
// The same for a two-dimensional table: its search squares are wider (fields far off both axes)
// and a ghost's light near a vignetting onset narrows to a sliver the coarser pass misses.
constexpr int kCoarse2D = 72;
constexpr int kMinGrid = 16;    // the coarsest grid a ghost's mesh gets
constexpr int kDirectGrid = 96; // cells per side of the direct path's mesh (its flux normalises)

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

// The flux of a mesh: the weight integrated over the lit part of every traced triangle of every
// cell (cellTriangles; in cells, the caller scales by the cell's area). With `land`, also the flux's
// first moment of the landing y (each clipped triangle's weight spread uniformly over its image, as
// drawn: its share times the landing y at the clipped polygon's centroid).
template <typename Constraints>
double meshFlux(int n, const std::vector<char>& ok, const std::vector<double>& weight, std::size_t constraints,
                Constraints&& value, const std::vector<glm::dvec2>* land = nullptr, double* momentY = nullptr) {
    TriangleClipper clipper;
    std::vector<std::array<double, 3>> c(constraints);
    double sum = 0.0, sumY = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t v00 = static_cast<std::size_t>(j) * (n + 1) + i, v10 = v00 + 1, v01 = v00 + n + 1,
                              v11 = v01 + 1;
            const std::array<std::size_t, 4> corners{v00, v10, v01, v11};
            for (const auto& tri : cellTriangles(ok[v00], ok[v10], ok[v01], ok[v11])) {
                if (tri[0] >= 4) continue;
                const std::array<std::size_t, 3> t{corners[tri[0]], corners[tri[1]], corners[tri[2]]};
                // Only the constraints that cut the triangle clip it; one it lies wholly outside darkens it.
                std::size_t active = 0;
                bool dark = false;
                for (std::size_t k = 0; k < constraints && !dark; ++k) {
                    const std::array<double, 3> v{value(t[0], k), value(t[1], k), value(t[2], k)};
                    dark = v[0] < 0.0 && v[1] < 0.0 && v[2] < 0.0;
                    if (v[0] < 0.0 || v[1] < 0.0 || v[2] < 0.0) c[active++] = v;
                }
                if (dark) continue;
                const double share = active == 0 ? 1.0 : clipper.clip(c.data(), active);
                const double e = share * 0.5 * (weight[t[0]] + weight[t[1]] + weight[t[2]]) / 3.0;
                sum += e;
                if (!land || !(e > 0.0)) continue;
                // The clipped polygon's centroid in barycentrics (the area-weighted mean of a fan).
                glm::dvec3 centroid(0.0);
                double area = 0.0;
                for (std::size_t q = 1; active > 0 && q + 1 < clipper.size(); ++q) {
                    const glm::dvec3 &A = clipper[0], &B = clipper[q], &C = clipper[q + 1];
                    const double a = std::abs((B.y - A.y) * (C.z - A.z) - (C.y - A.y) * (B.z - A.z));
                    centroid += a * (A + B + C) / 3.0;
                    area += a;
                }
                if (area > 0.0)
                    centroid /= area;
                else
                    centroid = glm::dvec3(1.0 / 3.0);
                sumY +=
                    e * (centroid.x * (*land)[t[0]].y + centroid.y * (*land)[t[1]].y + centroid.z * (*land)[t[2]].y);
            }
        }
    if (momentY) *momentY = sumY;
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
    Rect square; ///< the square searched
};

Probe probe(const trace::LensAtWavelength& L, const std::vector<trace::PathStep>& steps, const trace::PupilFrame& pupil,
            const trace::Field& field, int n = kCoarse) {
    const double h = trace::searchHalfSize(pupil, field);
    const RayMaker rays(pupil, field);
    const OpenMesh m = traceMesh(L, steps, rays, {-h, -h, h, h}, n);
    constexpr double inf = std::numeric_limits<double>::infinity();
    Rect box{inf, inf, -inf, -inf}, land{inf, inf, -inf, -inf};
    const double cell = 2.0 * h / n;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const std::size_t v = static_cast<std::size_t>(j) * (n + 1) + i;
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
    out.square = {-h, -h, h, h};
    if (!(box.x1 > box.x0)) return out;
    out.rect = {std::max(box.x0, -h), std::max(box.y0, -h), std::min(box.x1, h), std::min(box.y1, h)};
    out.flux = cell * cell * meshFlux(n, m.ok, m.weight, m.steps, marginsOf(m));
    out.landingArea = (land.x1 - land.x0) * (land.y1 - land.y0);
    return out;
}

// The direct image at one field and wavelength: its flux (pupil mm^2 x weight), its apertures' edges
// clipped as the ghosts' are, and its centroid's y (mm).
struct Direct {
    double flux = 0.0, y = 0.0;
};

Direct directImage(const trace::LensAtWavelength& L, const std::vector<trace::PathStep>& steps,
                   const trace::PupilFrame& pupil, const trace::Field& field, std::size_t& rays) {
    const Rect r = probe(L, steps, pupil, field).rect;
    rays += (kCoarse + 1) * (kCoarse + 1);
    if (r.empty()) return {};
    const OpenMesh m = traceMesh(L, steps, RayMaker(pupil, field), r, kDirectGrid);
    rays += m.ok.size();
    const double cellArea = (r.x1 - r.x0) * (r.y1 - r.y0) / (double(kDirectGrid) * kDirectGrid);
    double momentY = 0.0;
    const double flux = meshFlux(kDirectGrid, m.ok, m.weight, m.steps, marginsOf(m), &m.land, &momentY);
    return {cellArea * flux, flux > 0.0 ? momentY / flux : 0.0};
}

} // namespace

std::size_t ShapedTable::bytes() const {
    std::size_t b = 0;
    for (const ShapedGhost& g : ghosts)
        for (const auto& w : g.meshes)
            for (const ShapedMesh& m : w) b += m.data.size() * sizeof(float);
    return b;
}

std::string shapedCacheKey(const optics::Lens& lens, const TableSettings& s) {
    // Changes whenever the table built for the same settings changes.
    constexpr int kBuildVersion = 10;
    const auto sensor = s.sensorSizeMm.value_or(lens.sensorMm.value_or(std::make_pair(36.0, 24.0)));
    std::string k = "shaped " + std::to_string(kBuildVersion) + "|lens " + lens.contentHash + "|zoom " +
                    std::to_string(lens.activeZoom) + "|wavelengths";
    for (double w : s.wavelengthsNm) k += " " + text::roundTrip(w);
    k += "|grid " + std::to_string(s.grid) + "|angles " + std::to_string(s.angles) + "|max " +
         text::roundTrip(s.maxAngleDeg) + "|sensor " + std::to_string(static_cast<int>(s.sensor)) + "|coating " +
         std::to_string(static_cast<int>(s.coating)) + "|size " + text::roundTrip(sensor.first) + "x" +
         text::roundTrip(sensor.second) + "|store " + text::roundTrip(s.storeFraction);
    return k;
}

namespace {

// The field of the table's angle a of A, uniform from 0 to maxAngleDeg.
trace::Field tableField(double maxAngleDeg, std::size_t a, std::size_t A) {
    return trace::Field{degToRad(maxAngleDeg * double(a) / double(A - 1)), 0.0};
}

// The field of tangents (tx, ty) (ShapedTable::FieldGrid).
trace::Field tangentField(double tx, double ty) {
    return trace::Field{std::atan(std::hypot(tx, ty)), tx == 0.0 && ty == 0.0 ? 0.0 : std::atan2(-tx, ty)};
}

// The field of a table's field index a of A: an angle, or a point of its field grid.
trace::Field fieldOf(const ShapedTable& t, std::size_t a, std::size_t A) {
    if (!t.twoDimensional()) return tableField(t.maxAngleDeg, a, A);
    const auto& g = t.fieldGrid;
    const std::size_t X = static_cast<std::size_t>(g.x);
    return tangentField(g.maxTanX * double(a % X) / (g.x - 1), g.maxTanY * double(a / X) / (g.y - 1));
}

// An anamorphic lens's field grid: per axis its tangent where the chief ray lands 5 % beyond the
// sensor's half-width (half-height) on the axis and at the corner, the larger (or tan maxAngleDeg
// on both when given); fields spaced on the sensor as a symmetric table's `angles` are along the
// half-diagonal, at least 3 per axis. (Twice that spacing put the bicubic's error between fields at
// 0.16-0.21 relative L2 off the axes and 1.2 times the traced flux near a corner: docs/anamorphic.md.)
ShapedTable::FieldGrid anamorphicGrid(const optics::Lens& lens, double sensorZ, std::pair<double, double> sensor,
                                      const TableSettings& s) {
    ShapedTable::FieldGrid g;
    const double hx = 0.525 * sensor.first, hy = 0.525 * sensor.second;
    if (s.maxAngleDeg > 0.0) {
        g.maxTanX = g.maxTanY = std::tan(degToRad(s.maxAngleDeg));
    } else {
        const double fx = std::abs(optics::paraxialEfl(optics::sectionOf(lens, optics::Section::X), lines::d));
        const double fy = std::abs(optics::paraxialEfl(optics::sectionOf(lens, optics::Section::Y), lines::d));
        const auto tangents = [&](double x, double y) {
            try {
                const trace::Field f = trace::fieldForSensorPoint(lens, sensorZ, x, y);
                const double t = std::tan(f.angleRad);
                return glm::dvec2(std::abs(t * std::sin(f.azimuthRad)), std::abs(t * std::cos(f.azimuthRad)));
            } catch (const Error&) {
                return glm::dvec2(x / fx, y / fy); // no chief ray reaches it: the paraxial field
            }
        };
        const glm::dvec2 ex = tangents(hx, 0.0), ey = tangents(0.0, hy), corner = tangents(hx, hy);
        g.maxTanX = std::max(ex.x, corner.x);
        g.maxTanY = std::max(ey.y, corner.y);
    }
    const double spacing = std::hypot(hx, hy) / std::max(1, s.angles - 1);
    g.x = std::max(3, static_cast<int>(std::ceil(hx / spacing)) + 1);
    g.y = std::max(3, static_cast<int>(std::ceil(hy / spacing)) + 1);
    return g;
}

// A two-dimensional table's pupil rectangles of one ghost, per field of the grid: each side a
// biquadratic in the field's grid position (bilinear below 18 lit fields, constant below 4), fitted
// by least squares to the sides of the probes' boxes where the ghost is lit (probes[first + a]),
// then moved out until the rectangles contain every such box, and kept within each field's searched
// square (at a field not probed, or where the probe found no light — the ghost may still hold a
// sliver narrower than its spacing near a vignetting onset —, the rectangle follows the fit);
// `bounds` (the union of the boxes) where no fit can be made. Smooth over the field, they keep each
// vertex of the mesh a pupil point moving smoothly with it, which the bicubic interpolation between
// fields follows; one rectangle for all the fields of a quadrant would cover 5 to 17 times the area
// a field's light needs (the pupil point of a field's light moves with its tangent:
// docs/anamorphic.md).
std::vector<Rect> smoothRects(const std::vector<Probe>& probes, std::size_t first, const ShapedTable::FieldGrid& grid,
                              const std::vector<std::size_t>& lit, const Rect& bounds) {
    const std::size_t A = static_cast<std::size_t>(grid.x * grid.y);
    const auto uv = [&](std::size_t a) {
        return glm::dvec2(double(a % grid.x) / (grid.x - 1), double(a / grid.x) / (grid.y - 1));
    };
    int degree = lit.size() >= 18 ? 2 : lit.size() >= 4 ? 1 : 0;
    std::array<std::vector<double>, 4> fits;
    for (; degree >= 0; --degree) {
        bool ok = true;
        for (int side = 0; side < 4 && ok; ++side) {
            std::vector<glm::dvec3> points;
            for (std::size_t a : lit) {
                const Rect& r = probes[first + a].rect;
                const double z[4] = {r.x0, r.y0, r.x1, r.y1};
                points.push_back({uv(a), z[side]});
            }
            fits[side] = fitPolynomial(points, degree);
            ok = !fits[side].empty();
        }
        if (ok) break;
    }
    if (degree < 0) return std::vector<Rect>(A, bounds);
    // Moved out by the largest amount a box reaches beyond its fitted side.
    std::array<double, 4> out{};
    for (std::size_t a : lit) {
        const Rect& r = probes[first + a].rect;
        const glm::dvec2 p = uv(a);
        out[0] = std::max(out[0], polynomialAt(fits[0], degree, p.x, p.y) - r.x0);
        out[1] = std::max(out[1], polynomialAt(fits[1], degree, p.x, p.y) - r.y0);
        out[2] = std::max(out[2], r.x1 - polynomialAt(fits[2], degree, p.x, p.y));
        out[3] = std::max(out[3], r.y1 - polynomialAt(fits[3], degree, p.x, p.y));
    }
    std::vector<Rect> rects(A);
    for (std::size_t a = 0; a < A; ++a) {
        const glm::dvec2 p = uv(a);
        const Rect& square = probes[first + a].square;
        Rect r{std::max(square.x0, polynomialAt(fits[0], degree, p.x, p.y) - out[0]),
               std::max(square.y0, polynomialAt(fits[1], degree, p.x, p.y) - out[1]),
               std::min(square.x1, polynomialAt(fits[2], degree, p.x, p.y) + out[2]),
               std::min(square.y1, polynomialAt(fits[3], degree, p.x, p.y) + out[3])};
        rects[a] = r.empty() ? bounds : r;
    }
    return rects;
}

// One ghost's meshes at every wavelength and field, n cells per side over the pupil rectangle
// rects[a] (the same at every angle of a rotationally symmetric lens's table), weights relative to the direct image's
// flux direct[w * A + a]; the apertures that cut it somewhere kept. Adds the rays traced to `rays` and the largest mesh
// flux to `peak`.
ShapedGhost traceGhost(const optics::Lens& lens, const std::vector<trace::LensAtWavelength>& Ls,
                       const trace::GhostPair& pair, int n, const std::vector<Rect>& rects,
                       const trace::PupilFrame& pupil, const std::vector<trace::Field>& fields,
                       const std::vector<double>& direct, std::size_t& rays, double& peak) {
    const std::size_t W = Ls.size(), A = rects.size();
    ShapedGhost out;
    out.pair = pair;
    if (n == 0) return out;
    out.grid = n;
    out.pupilX0 = rects[0].x0, out.pupilY0 = rects[0].y0;
    out.pupilX1 = rects[0].x1, out.pupilY1 = rects[0].y1;
    const auto steps = trace::pathSteps(lens, pair);
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
            const Rect& r = rects[a];
            OpenMesh m = traceMesh(Ls[w], steps, RayMaker(pupil, fields[a]), r, n);
            rays += m.ok.size();
            const double cellArea = (r.x1 - r.x0) * (r.y1 - r.y0) / (double(n) * n);
            const double scale = direct[w * A + a] > 0.0 ? cellArea / direct[w * A + a] : 0.0;
            for (double& x : m.weight) x *= scale;
            out.meshes[w][a].flux = meshFlux(n, m.ok, m.weight, m.steps, marginsOf(m));
            peak = std::max(peak, out.meshes[w][a].flux);
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
    return out;
}

} // namespace

bool ShapedTable::covers(const trace::Field& f) const {
    constexpr double kSlack = 1.0 + 1e-9;
    if (!twoDimensional()) return radToDeg(f.angleRad) <= maxAngleDeg * kSlack;
    const double t = std::tan(f.angleRad);
    return std::abs(t * std::sin(f.azimuthRad)) <= fieldGrid.maxTanX * kSlack &&
           std::abs(t * std::cos(f.azimuthRad)) <= fieldGrid.maxTanY * kSlack;
}

namespace {

// Whether the table probes field a: every field of a symmetric table; every other field per axis,
// and the last, of a two-dimensional one.
bool probedField(const ShapedTable& table, std::size_t a) {
    if (!table.twoDimensional()) return true;
    const int X = table.fieldGrid.x, Y = table.fieldGrid.y, ix = static_cast<int>(a) % X, iy = static_cast<int>(a) / X;
    return (ix % 2 == 0 || ix == X - 1) && (iy % 2 == 0 || iy == Y - 1);
}

// Every ghost's probe at every field, [ghost * fields + field], at one wavelength; a field not
// probed (probedField) keeps only its searched square.
std::vector<Probe> probeGhosts(const ShapedTable& table, const optics::Lens& lens, const trace::LensAtWavelength& L,
                               const std::vector<trace::GhostPair>& pairs, const trace::PupilFrame& pupil,
                               const std::vector<trace::Field>& fields) {
    const std::size_t A = fields.size();
    const int grid = table.twoDimensional() ? kCoarse2D : kCoarse;
    std::vector<Probe> probes(pairs.size() * A);
    tbb::parallel_for(std::size_t(0), probes.size(), [&](std::size_t t) {
        if (probedField(table, t % A)) {
            probes[t] = probe(L, trace::pathSteps(lens, pairs[t / A]), pupil, fields[t % A], grid);
        } else {
            const double h = trace::searchHalfSize(pupil, fields[t % A]);
            probes[t].square = {-h, -h, h, h};
        }
    });
    return probes;
}

} // namespace

ShapedTable traceShapedTable(const optics::Lens& lensIn, const TableSettings& s, const Progress& progress) {
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
    table.sensorZ = sensorZ;
    table.sensorSizeMm = s.sensorSizeMm.value_or(lens.sensorMm.value_or(std::make_pair(36.0, 24.0)));
    if (lens.rotationallySymmetric()) {
        table.maxAngleDeg =
            s.maxAngleDeg > 0.0 ? s.maxAngleDeg : trace::sensorCornerFieldDeg(lens, sensorZ, table.sensorSizeMm);
    } else {
        table.fieldGrid = anamorphicGrid(lens, sensorZ, table.sensorSizeMm, s);
        table.maxAngleDeg = radToDeg(std::atan(std::hypot(table.fieldGrid.maxTanX, table.fieldGrid.maxTanY)));
    }
    table.iris = trace::LensAtWavelength(lens, lines::d, sensorZ, trace::LensAtWavelength::Films::Exact).iris;
    const trace::PupilFrame pupil = trace::pupilFrame(lens);
    table.pupilRadiusMm = pupil.radius;
    const auto pairs = trace::enumerateGhosts(lens);
    table.ghostCount = pairs.size();
    std::vector<trace::LensAtWavelength> Ls;
    for (double l : s.wavelengthsNm) Ls.emplace_back(lens, l, sensorZ);
    const std::size_t W = Ls.size(), G = pairs.size();
    const std::size_t A = table.twoDimensional() ? static_cast<std::size_t>(table.fieldGrid.x * table.fieldGrid.y)
                                                 : static_cast<std::size_t>(s.angles);
    std::vector<trace::Field> fields(A);
    for (std::size_t a = 0; a < A; ++a) fields[a] = fieldOf(table, a, A);
    auto fieldAt = [&](std::size_t a) { return fields[a]; };

    // The direct image's flux and centroid per wavelength and angle.
    const auto directSteps = trace::pathSteps(lens, std::nullopt);
    std::vector<double> direct(W * A, 0.0);
    std::vector<std::size_t> rays(G + W * A, 0);
    table.directY.assign(W, std::vector<double>(A, 0.0));
    tbb::parallel_for(std::size_t(0), W * A, [&](std::size_t t) {
        const Direct d = directImage(Ls[t / A], directSteps, pupil, fieldAt(t % A), rays[G + t]);
        direct[t] = d.flux;
        table.directY[t / A][t % A] = d.y;
    });
    if (table.twoDimensional())
        for (std::size_t w = 0; w < W; ++w)
            table.directFlux.emplace_back(direct.begin() + static_cast<std::ptrdiff_t>(w * A),
                                          direct.begin() + static_cast<std::ptrdiff_t>((w + 1) * A));

    // Where each ghost's light is at each angle, probed at the middle wavelength. A ghost's meshes
    // all cover the rectangle over its light at every angle: a vertex is then the same pupil point at
    // every angle, and interpolating between angles follows that ray (rectangles fitted per angle
    // move in steps of the probe's spacing, and a vertex interpolated between two of them mixes two
    // rays; docs/ghost-table.md, "One rectangle per angle"). A two-dimensional table's rectangles
    // follow the light smoothly over the field instead (smoothRects), fitted to the probes of every
    // other field per axis and the last (a quarter of the rays; the fit is a biquadratic over the
    // field whichever fields it is fitted to); the other fields keep only their searched square.
    const std::size_t mid = W / 2;
    std::vector<Probe> probes = probeGhosts(table, lens, Ls[mid], pairs, pupil, fields);
    const int probeGrid = table.twoDimensional() ? kCoarse2D : kCoarse;
    std::size_t probedFields = 0;
    for (std::size_t a = 0; a < A; ++a) probedFields += probedField(table, a) ? 1 : 0;
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
            importance[g] += f * f / std::max(p.landingArea, minArea) / double(probedFields);
        }
        if (lit.empty()) continue;
        Rect u = probes[g * A + lit.front()].rect;
        for (std::size_t a : lit) {
            const Rect& r = probes[g * A + a].rect;
            u = {std::min(u.x0, r.x0), std::min(u.y0, r.y0), std::max(u.x1, r.x1), std::max(u.y1, r.y1)};
        }
        if (table.twoDimensional())
            rects[g] = smoothRects(probes, g * A, table.fieldGrid, lit, u);
        else
            rects[g].assign(A, u);
    }
    const std::size_t rayCount = G * probedFields * (probeGrid + 1) * (probeGrid + 1);
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
        ghosts[g] = traceGhost(lens, Ls, pairs[g], grids[g], rects[g], pupil, fields, direct, rays[g], peak[g]);
        if (progress) progress(++done, 2 * G);
    });
    const double strongest = G ? *std::max_element(peak.begin(), peak.end()) : 0.0;
    for (std::size_t g = 0; g < G; ++g)
        if (peak[g] > 0.0 && peak[g] >= s.storeFraction * strongest) table.ghosts.push_back(std::move(ghosts[g]));
    table.rays = rayCount + std::accumulate(rays.begin(), rays.end(), std::size_t(0));
    table.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return table;
}

} // namespace ff::ghosts
