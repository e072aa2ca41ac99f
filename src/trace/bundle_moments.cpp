#include "trace/bundle_moments.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ff::trace {

namespace {

// Whether a ray's landing point is within maxRadius of the axis (0: no limit).
bool landsWithin(const RayResult& r, double maxRadius) {
    return maxRadius <= 0.0 || r.sensorPoint.x * r.sensorPoint.x + r.sensorPoint.y * r.sensorPoint.y <= maxRadius * maxRadius;
}

} // namespace

BundleMoments measureSamples(std::span<const RayResult> hits, std::span<const double> areas, double scale, double maxRadius) {
    BundleMoments m;
    auto counts = [&](const RayResult& r) { return landsWithin(r, maxRadius); };
    double sx = 0.0, sy = 0.0;
    for (std::size_t i = 0; i < hits.size(); ++i) {
        if (areas[i] <= 0.0) continue;
        ++m.launched;
        const RayResult& r = hits[i];
        if (r.status == optics::RayStatus::Blocked) ++m.blocked;
        if (r.status != optics::RayStatus::Ok) continue;
        ++m.surviving;
        if (!counts(r)) continue;
        const double w = r.weight * areas[i] * scale;
        m.energy += w;
        sx += w * r.sensorPoint.x;
        sy += w * r.sensorPoint.y;
    }
    if (m.energy <= 0.0) return m;
    m.centroidX = sx / m.energy;
    m.centroidY = sy / m.energy;
    for (std::size_t i = 0; i < hits.size(); ++i) {
        const RayResult& r = hits[i];
        if (areas[i] <= 0.0 || r.status != optics::RayStatus::Ok || !counts(r)) continue;
        const double w = r.weight * areas[i] * scale;
        const double dx = r.sensorPoint.x - m.centroidX, dy = r.sensorPoint.y - m.centroidY;
        m.mxx += w * dx * dx;
        m.myy += w * dy * dy;
        m.mxy += w * dx * dy;
    }
    m.mxx /= m.energy;
    m.myy /= m.energy;
    m.mxy /= m.energy;
    return m;
}

BundleMoments measureBundle(const Bundle& b, const std::vector<RayResult>& hits, double scale, double maxRadius) {
    std::vector<double> areas(hits.size());
    for (std::size_t i = 0; i < hits.size(); ++i) areas[i] = b.launched[i] ? b.cellArea : 0.0;
    return measureSamples(hits, areas, scale, maxRadius);
}

BundleMoments combineMoments(std::span<const BundleMoments> parts) {
    BundleMoments m;
    double sx = 0.0, sy = 0.0;
    for (const BundleMoments& p : parts) {
        m.launched += p.launched, m.surviving += p.surviving, m.blocked += p.blocked;
        m.energy += p.energy;
        sx += p.energy * p.centroidX, sy += p.energy * p.centroidY;
    }
    if (m.energy <= 0.0) return m;
    m.centroidX = sx / m.energy, m.centroidY = sy / m.energy;
    for (const BundleMoments& p : parts) {
        const double dx = p.centroidX - m.centroidX, dy = p.centroidY - m.centroidY;
        m.mxx += p.energy * (p.mxx + dx * dx);
        m.myy += p.energy * (p.myy + dy * dy);
        m.mxy += p.energy * (p.mxy + dx * dy);
    }
    m.mxx /= m.energy, m.myy /= m.energy, m.mxy /= m.energy;
    return m;
}

BundleMoments measureBundleResolved(const EmbreeTracer& tracer, const LensAtWavelength& L, const std::vector<PathStep>& steps,
                                    const PupilFrame& pupil, const Field& field, const Bundle& centres, const std::vector<RayResult>& c,
                                    const std::vector<RayResult>& k, int subdivisions, double scale, double maxRadius) {
    // Cells whose centre and corners disagree on whether their light counts: lost or not, and
    // inside maxRadius or not (a wide ghost cut there moves in steps just as one cut by a stop).
    // A cell on the ghost's own edge (some of its rays lost) is resolved too where the counting circle
    // passes within the cell's image of one of its landing points: there a sliver of light between the
    // edge and the circle can narrow to a tip between the rays, all of whose arriving rays land beyond
    // the circle, and the tips carry much of the sliver's tangential spread. (Cells all of whose rays
    // arrive are left to the centre-and-corners test, which catches the circle once it reaches one of
    // their rays, having cut off no more than a corner between them.)
    auto counted = [&](const RayResult& r) { return r.status == optics::RayStatus::Ok && landsWithin(r, maxRadius); };
    const int n = centres.n;
    auto cellRays = [&](int i, int j) {
        const std::size_t corner = static_cast<std::size_t>(j) * (n + 1) + i;
        return std::array<const RayResult*, 5>{&c[static_cast<std::size_t>(j) * n + i], &k[corner], &k[corner + 1], &k[corner + n + 1],
                                               &k[corner + n + 2]};
    };
    // The diameter of a cell's image on the sensor (its arriving rays' landing points), 0 with fewer than two.
    auto imageSize = [](const std::array<const RayResult*, 5>& rays) {
        double d2 = 0.0;
        for (std::size_t a = 0; a < rays.size(); ++a)
            for (std::size_t b = a + 1; b < rays.size(); ++b)
                if (rays[a]->status == optics::RayStatus::Ok && rays[b]->status == optics::RayStatus::Ok) {
                    const double dx = rays[a]->sensorPoint.x - rays[b]->sensorPoint.x, dy = rays[a]->sensorPoint.y - rays[b]->sensorPoint.y;
                    d2 = std::max(d2, dx * dx + dy * dy);
                }
        return std::sqrt(d2);
    };
    // A cell with one arriving ray takes the bundle's median cell image.
    double typicalSize = 0.0;
    if (maxRadius > 0.0) {
        std::vector<double> sizes;
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                if (const double d = imageSize(cellRays(i, j)); d > 0.0) sizes.push_back(d);
        if (!sizes.empty()) {
            std::nth_element(sizes.begin(), sizes.begin() + static_cast<std::ptrdiff_t>(sizes.size() / 2), sizes.end());
            typicalSize = sizes[sizes.size() / 2];
        }
    }
    std::vector<char> edge(c.size(), 0);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const auto rays = cellRays(i, j);
            int in = 0, arriving = 0;
            for (const RayResult* r : rays) in += counted(*r), arriving += r->status == optics::RayStatus::Ok;
            bool straddles = in > 0 && in < 5;
            if (!straddles && maxRadius > 0.0 && arriving > 0 && arriving < 5) {
                const double d = imageSize(rays), reach = d > 0.0 ? d : typicalSize;
                for (const RayResult* r : rays)
                    straddles = straddles || (r->status == optics::RayStatus::Ok &&
                                              std::abs(std::hypot(r->sensorPoint.x, r->sensorPoint.y) - maxRadius) <= reach);
            }
            edge[static_cast<std::size_t>(j) * n + i] = straddles;
        }
    std::vector<RayResult> hits;
    std::vector<double> areas;
    std::vector<optics::Ray> subRays;
    const double subArea = centres.cellArea / (double(subdivisions) * subdivisions);
    for (std::size_t i = 0; i < c.size(); ++i) {
        if (!centres.launched[i]) continue;
        const int col = static_cast<int>(i % static_cast<std::size_t>(centres.n)), row = static_cast<int>(i / static_cast<std::size_t>(centres.n));
        if (!edge[i]) {
            if (!counted(c[i])) continue;
            // A wholly lit cell: 2/3 of the midpoint rule plus 1/3 of its corners' trapezoid rule,
            // whose h^2 error terms cancel (a strongly curved landing map is then integrated to
            // fourth order instead of second).
            hits.push_back(c[i]);
            areas.push_back(centres.cellArea * (2.0 / 3.0));
            const std::size_t corner = static_cast<std::size_t>(row) * (n + 1) + col;
            for (const std::size_t q : {corner, corner + 1, corner + n + 1, corner + n + 2}) {
                hits.push_back(k[q]);
                areas.push_back(centres.cellArea / 12.0);
            }
            continue;
        }
        const Bundle sub = gridBundle(pupil, field, subdivisions, centres.x0 + (col + 0.5) * centres.cell, centres.y0 + (row + 0.5) * centres.cell,
                                      0.5 * centres.cell, false);
        subRays.insert(subRays.end(), sub.rays.begin(), sub.rays.end());
    }
    if (!subRays.empty()) {
        std::vector<RayResult> subHits(subRays.size());
        tracer.trace(L, steps, subRays, subHits);
        hits.insert(hits.end(), subHits.begin(), subHits.end());
        areas.insert(areas.end(), subHits.size(), subArea);
    }
    BundleMoments m = measureSamples(hits, areas, scale, maxRadius);
    // The counts are the grid's centre rays'.
    m.launched = m.surviving = m.blocked = 0;
    for (std::size_t i = 0; i < c.size(); ++i) {
        if (!centres.launched[i]) continue;
        ++m.launched;
        m.surviving += c[i].status == optics::RayStatus::Ok;
        m.blocked += c[i].status == optics::RayStatus::Blocked;
    }
    return m;
}

} // namespace ff::trace
