#include "trace/open_trace.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace ff::trace {

using optics::RayStatus;

namespace {

// One ray's open trace into res and margins[0, steps).
void traceOpenRay(const LensAtWavelength& L, const std::vector<PathStep>& steps, const optics::Ray& ray, RayResult& res,
                  double* margins) {
    const SequentialResult r = traceSequential(L, steps, ray, Weighting::Fresnel, margins);
    res = RayResult{r.status, r.lostAtStep, r.status == RayStatus::Ok ? r.ray.origin : glm::dvec3(0.0), r.ray.dir,
                    r.weight};
}

} // namespace

OpenTrace traceOpen(const LensAtWavelength& L, const std::vector<PathStep>& steps, std::span<const optics::Ray> rays) {
    OpenTrace t;
    t.steps = steps.size();
    t.hits.resize(rays.size());
    t.margins.resize(rays.size() * steps.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i < r.end(); ++i)
                              traceOpenRay(L, steps, rays[i], t.hits[i], &t.margins[i * steps.size()]);
                      });
    return t;
}

double feasibleShare(std::span<const HalfPlane> constraints, glm::dvec2* centroid) {
    if (constraints.empty()) { // the whole square (most sub-cells)
        if (centroid) *centroid = glm::dvec2(0.0);
        return 1.0;
    }
    // A convex polygon stays convex under each cut; the square has 4 vertices and each cut adds at
    // most one.
    std::vector<std::array<double, 2>> poly{{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}}, next;
    for (const HalfPlane& h : constraints) {
        auto g = [&](const std::array<double, 2>& p) { return h.value + h.du * p[0] + h.dv * p[1]; };
        next.clear();
        for (std::size_t a = 0; a < poly.size(); ++a) {
            const std::array<double, 2>& p = poly[a];
            const std::array<double, 2>& q = poly[(a + 1) % poly.size()];
            const double gp = g(p), gq = g(q);
            if (gp >= 0.0) next.push_back(p);
            if ((gp >= 0.0) != (gq >= 0.0)) {
                const double s = gp / (gp - gq);
                next.push_back({p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1])});
            }
        }
        poly.swap(next);
        if (poly.size() < 3) return 0.0;
    }
    double twice = 0.0, cu = 0.0, cv = 0.0;
    for (std::size_t a = 0; a < poly.size(); ++a) {
        const std::array<double, 2>& p = poly[a];
        const std::array<double, 2>& q = poly[(a + 1) % poly.size()];
        const double cross = p[0] * q[1] - q[0] * p[1];
        twice += cross;
        cu += (p[0] + q[0]) * cross, cv += (p[1] + q[1]) * cross;
    }
    if (centroid && twice > 0.0) *centroid = glm::dvec2(cu / (3.0 * twice), cv / (3.0 * twice));
    return std::clamp(0.5 * twice, 0.0, 1.0);
}

namespace {

// Ray i's margins, and the counting circle's as one more (index t.steps), NaN where unknown.
double marginOf(const OpenTrace& t, std::size_t i, std::size_t k, double maxRadius) {
    if (k < t.steps) return t.margin(i, k);
    const RayResult& r = t.hits[i];
    if (r.status != RayStatus::Ok) return std::numeric_limits<double>::quiet_NaN();
    return maxRadius > 0.0 ? maxRadius - std::hypot(r.sensorPoint.x, r.sensorPoint.y)
                           : std::numeric_limits<double>::infinity();
}

} // namespace

std::vector<double> subCellShares(const OpenTrace& t, std::size_t first, int sub, double maxRadius,
                                  std::vector<glm::dvec2>* centroids) {
    const std::size_t count = static_cast<std::size_t>(sub) * sub;
    std::vector<double> shares(count, 0.0);
    if (centroids) centroids->assign(count, glm::dvec2(0.0));
    std::vector<HalfPlane> cut;
    for (int sj = 0; sj < sub; ++sj)
        for (int si = 0; si < sub; ++si) {
            const std::size_t i = first + static_cast<std::size_t>(sj) * sub + si;
            if (t.hits[i].status != RayStatus::Ok) continue;
            cut.clear();
            bool out = false;
            for (std::size_t k = 0; k <= t.steps && !out; ++k) {
                const double m = marginOf(t, i, k, maxRadius);
                if (std::isinf(m)) continue; // an unclipped surface, or no counting radius
                // The slope along one axis, per sub-cell, from the neighbours traced through step k.
                auto slope = [&](int di, int dj) {
                    double sum = 0.0;
                    int n = 0;
                    for (const int s : {-1, 1}) {
                        const int ni = si + s * di, nj = sj + s * dj;
                        if (ni < 0 || nj < 0 || ni >= sub || nj >= sub) continue;
                        const double o = marginOf(t, first + static_cast<std::size_t>(nj) * sub + ni, k, maxRadius);
                        if (std::isnan(o) || std::isinf(o)) continue;
                        sum += s * (o - m);
                        ++n;
                    }
                    return n > 0 ? sum / n : 0.0;
                };
                const HalfPlane h{m, slope(1, 0), slope(0, 1)};
                const double span = 0.5 * (std::abs(h.du) + std::abs(h.dv));
                if (m >= span) continue; // the whole sub-cell is inside
                if (m <= -span) out = true;
                cut.push_back(h);
            }
            if (!out) shares[i - first] = feasibleShare(cut, centroids ? &(*centroids)[i - first] : nullptr);
        }
    return shares;
}

bool mayHoldLight(const OpenTrace& t, std::size_t first, double maxRadius) {
    for (std::size_t r = first; r < first + 5; ++r)
        if (t.hits[r].status != RayStatus::Ok) return false;
    std::vector<HalfPlane> cut;
    for (std::size_t k = 0; k <= t.steps; ++k) {
        std::array<double, 5> m;
        for (std::size_t r = 0; r < 5; ++r) m[r] = marginOf(t, first + r, k, maxRadius);
        if (std::isinf(m[0])) continue;
        const double du = 0.5 * ((m[2] + m[4]) - (m[1] + m[3])), dv = 0.5 * ((m[3] + m[4]) - (m[1] + m[2]));
        const double slack = std::abs(m[0] - 0.25 * (m[1] + m[2] + m[3] + m[4]));
        cut.push_back({m[0] + slack, du, dv});
    }
    return feasibleShare(cut) > 0.0;
}

std::vector<std::size_t> cellsWithRoomForLight(const LensAtWavelength& L, const std::vector<PathStep>& steps,
                                               const PupilFrame& pupil, const Field& field, const Bundle& centres,
                                               const std::vector<RayResult>& c, const std::vector<RayResult>& k,
                                               double maxRadius, const std::vector<char>& taken) {
    auto counted = [&](const RayResult& r) { return r.status == RayStatus::Ok && landsWithin(r, maxRadius); };
    // Why a dark ray is dark: the step and way it was lost, or (-1) landing beyond the circle.
    auto reason = [](const RayResult& r) {
        return r.status == RayStatus::Ok ? -1L
                                         : static_cast<long>(r.status) * 100000L + static_cast<long>(r.lostAtStep);
    };
    const int n = centres.n;
    std::vector<std::size_t> candidates;
    std::vector<optics::Ray> rays;
    for (int row = 0; row < n; ++row)
        for (int col = 0; col < n; ++col) {
            const std::size_t i = static_cast<std::size_t>(row) * n + col;
            if (taken[i] || !centres.launched[i]) continue;
            const std::size_t corner = static_cast<std::size_t>(row) * (n + 1) + col;
            const std::array<const RayResult*, 5> five{&c[i], &k[corner], &k[corner + 1], &k[corner + n + 1],
                                                       &k[corner + n + 2]};
            bool dark = true, mixed = false;
            for (const RayResult* r : five)
                dark = dark && !counted(*r), mixed = mixed || reason(*r) != reason(*five[0]);
            if (!dark || !mixed) continue;
            candidates.push_back(i);
            rays.push_back(centres.rays[i]);
            // The corners, (-,-), (+,-), (-,+), (+,+): a 2 x 2 grid over the square twice the cell's side.
            const Bundle corners = gridBundle(pupil, field, 2, centres.x0 + (col + 0.5) * centres.cell,
                                              centres.y0 + (row + 0.5) * centres.cell, centres.cell, false);
            rays.insert(rays.end(), corners.rays.begin(), corners.rays.end());
        }
    const OpenTrace open = traceOpen(L, steps, rays);
    std::vector<std::size_t> out;
    for (std::size_t q = 0; q < candidates.size(); ++q)
        if (mayHoldLight(open, 5 * q, maxRadius)) out.push_back(candidates[q]);
    return out;
}

SubGridTrace traceSubGrids(const EmbreeTracer& tracer, const LensAtWavelength& L, const std::vector<PathStep>& steps,
                           std::span<const optics::Ray> rays, std::span<const std::size_t> first,
                           std::span<const int> subs, double maxRadius) {
    SubGridTrace out;
    out.hits.resize(rays.size());
    out.share.assign(rays.size(), 0.0);
    // The ray traced by the Embree tracer for each sub-cell with light: the sub-ray itself where every
    // aperture passes it and it lands within the circle, else one through the centroid of the
    // sub-cell's lit part. (Sub-cells without light keep an empty hit: their share is 0.)
    std::vector<optics::Ray> probes(rays.size());
    std::vector<char> probed(rays.size(), 0);
    // Grid by grid, so that the margins of one grid's rays are held at a time.
    tbb::parallel_for(std::size_t(0), first.size(), [&](std::size_t q) {
        const int sub = subs[q];
        const std::size_t count = static_cast<std::size_t>(sub) * sub;
        OpenTrace t;
        t.steps = steps.size();
        t.hits.resize(count);
        t.margins.resize(count * steps.size());
        for (std::size_t i = 0; i < count; ++i)
            traceOpenRay(L, steps, rays[first[q] + i], t.hits[i], &t.margins[i * steps.size()]);
        std::vector<glm::dvec2> centroids;
        const std::vector<double> shares = subCellShares(t, 0, sub, maxRadius, &centroids);
        // The sub-cell's side: the rays of a grid are parallel, their origins a sub-cell apart.
        const double side = sub > 1 ? rays[first[q] + 1].origin.x - rays[first[q]].origin.x : 0.0;
        for (std::size_t i = 0; i < count; ++i) {
            const std::size_t r = first[q] + i;
            out.share[r] = shares[i];
            if (!(shares[i] > 0.0)) continue;
            bool clear = true;
            for (std::size_t k = 0; k <= steps.size() && clear; ++k)
                if (marginOf(t, i, k, maxRadius) < 0.0) clear = false;
            probes[r] = rays[r];
            if (!clear) probes[r].origin += glm::dvec3(centroids[i].x * side, centroids[i].y * side, 0.0);
            probed[r] = 1;
        }
    });
    std::vector<std::size_t> which;
    std::vector<optics::Ray> again;
    for (std::size_t r = 0; r < rays.size(); ++r)
        if (probed[r]) which.push_back(r), again.push_back(probes[r]);
    std::vector<RayResult> real(again.size());
    tracer.trace(L, steps, again, real);
    for (std::size_t a = 0; a < which.size(); ++a) {
        out.hits[which[a]] = real[a];
        if (real[a].status != RayStatus::Ok || !landsWithin(real[a], maxRadius)) out.share[which[a]] = 0.0;
    }
    return out;
}

} // namespace ff::trace
