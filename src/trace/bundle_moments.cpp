#include "trace/bundle_moments.h"

#include "trace/open_trace.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ff::trace {

namespace {

// Counted rays of one cell whose weights differ by more than this factor straddle a step in the
// weight, not a smooth change across the cell.
constexpr double kWeightStep = 2.0;

} // namespace

BundleMoments measureSamples(std::span<const RayResult> hits, std::span<const double> areas, double scale,
                             double maxRadius) {
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

BundleMoments measureBundleResolved(const EmbreeTracer& tracer, const LensAtWavelength& L,
                                    const std::vector<PathStep>& steps, const PupilFrame& pupil, const Field& field,
                                    const Bundle& centres, const std::vector<RayResult>& c,
                                    const std::vector<RayResult>& k, int subdivisions, double scale, double maxRadius,
                                    std::span<const glm::dvec2> litPoints) {
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
        return std::array<const RayResult*, 5>{&c[static_cast<std::size_t>(j) * n + i], &k[corner], &k[corner + 1],
                                               &k[corner + n + 1], &k[corner + n + 2]};
    };
    // The diameter of a cell's image on the sensor (its arriving rays' landing points), 0 with fewer than two.
    auto imageSize = [](const std::array<const RayResult*, 5>& rays) {
        double d2 = 0.0;
        for (std::size_t a = 0; a < rays.size(); ++a)
            for (std::size_t b = a + 1; b < rays.size(); ++b)
                if (rays[a]->status == optics::RayStatus::Ok && rays[b]->status == optics::RayStatus::Ok) {
                    const double dx = rays[a]->sensorPoint.x - rays[b]->sensorPoint.x,
                                 dy = rays[a]->sensorPoint.y - rays[b]->sensorPoint.y;
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
    constexpr char kEdgeCell = 1, kWeightStepCell = 2;
    constexpr int kWeightStepSub = 4;
    std::vector<char> edge(c.size(), 0);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const auto rays = cellRays(i, j);
            int in = 0, arriving = 0;
            for (const RayResult* r : rays) in += counted(*r), arriving += r->status == optics::RayStatus::Ok;
            bool straddles = in > 0 && in < 5;
            // A step in the rays' weight (a reflection turning total), in a cell all of whose rays
            // count or on the ghost's edge: the centre-and-corner rule would move it across whole
            // cells as the grid moves. Lit shares do not see such a line (no aperture's edge), so its
            // sub-cells count whole, on sub-grids kWeightStepSub times as dense
            // (docs/sampling-cases.md, "Weight steps").
            if (arriving >= 2) {
                double lo = 0.0, hi = 0.0;
                bool first = true;
                for (const RayResult* r : rays)
                    if (r->status == optics::RayStatus::Ok) {
                        lo = first ? r->weight : std::min(lo, r->weight),
                        hi = first ? r->weight : std::max(hi, r->weight);
                        first = false;
                    }
                if (hi > kWeightStep * lo) {
                    edge[static_cast<std::size_t>(j) * n + i] = kWeightStepCell;
                    continue;
                }
            }
            if (!straddles && maxRadius > 0.0 && arriving > 0 && arriving < 5) {
                const double d = imageSize(rays), reach = d > 0.0 ? d : typicalSize;
                for (const RayResult* r : rays)
                    straddles =
                        straddles || (r->status == optics::RayStatus::Ok &&
                                      std::abs(std::hypot(r->sensorPoint.x, r->sensorPoint.y) - maxRadius) <= reach);
            }
            if (straddles) edge[static_cast<std::size_t>(j) * n + i] = kEdgeCell;
        }
    // A step in the weight can run between a straddling cell's arriving rays and its border, where
    // none of them shows it: straddling cells beside a cell whose rays show one are resolved as
    // densely (docs/sampling-cases.md, "Weight steps on a cell's border").
    const std::vector<char> shown = edge;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            char& e = edge[static_cast<std::size_t>(j) * n + i];
            if (e != kEdgeCell) continue;
            for (int dj = -1; dj <= 1; ++dj)
                for (int di = -1; di <= 1; ++di) {
                    const int ni = i + di, nj = j + dj;
                    if (ni < 0 || nj < 0 || ni >= n || nj >= n) continue;
                    if (shown[static_cast<std::size_t>(nj) * n + ni] == kWeightStepCell) e = kWeightStepCell;
                }
        }
    std::vector<RayResult> hits;
    std::vector<double> areas;
    // Cells to trace on sub-grids, with their sub-grids' size.
    struct Resolve {
        std::size_t cell;
        int sub;
    };
    std::vector<Resolve> queue;
    for (std::size_t i = 0; i < c.size(); ++i) {
        if (!centres.launched[i]) continue;
        if (edge[i]) {
            queue.push_back({i, edge[i] == kWeightStepCell ? kWeightStepSub * subdivisions : subdivisions});
            continue;
        }
        if (!counted(c[i])) continue;
        // A wholly lit cell: 2/3 of the midpoint rule plus 1/3 of its corners' trapezoid rule,
        // whose h^2 error terms cancel (a strongly curved landing map is then integrated to
        // fourth order instead of second).
        const std::size_t col = i % static_cast<std::size_t>(n), row = i / static_cast<std::size_t>(n);
        hits.push_back(c[i]);
        areas.push_back(centres.cellArea * (2.0 / 3.0));
        const std::size_t corner = row * (n + 1) + col;
        for (const std::size_t q : {corner, corner + 1, corner + n + 1, corner + n + 2}) {
            hits.push_back(k[q]);
            areas.push_back(centres.cellArea / 12.0);
        }
    }
    // The straddling cells' sub-grids, then those of dark cells (none of their five rays counts)
    // into which a traced sub-grid's light reaches: a sub-cell on its border or corner holds light,
    // the cell beyond it is dark. Light thinner than the grid can pass between all five rays of a
    // cell (docs/sampling-cases.md, "Slivers between rays"); light is continuous, so it enters such
    // a cell across a border that a traced sub-grid sees it reach. (Light wholly inside one cell, between its rays, is
    // the region search's to find: a piece far from the rest gets a square and grid of its own.)
    std::vector<char> resolved(c.size(), 0);
    for (const Resolve& r : queue) resolved[r.cell] = 1;
    // Light in a dark cell passed between rays a cell apart: it is thin, and a sub-grid of the
    // straddling cells' density would put a row or two across it.
    const int darkSub = 2 * subdivisions;
    // Light that no straddling cell borders can still pass between the rays: a sliver under a cell
    // wide, far from the rest of the light. The region search's passes found it (its local passes,
    // or its jittered coarse pass; docs/sampling-cases.md, "Far slivers"); a dark cell holding one of
    // their lit points is resolved, and the flood below follows the light from there.
    for (const glm::dvec2& p : litPoints) {
        const double fx = (p.x - centres.x0) / centres.cell, fy = (p.y - centres.y0) / centres.cell;
        if (!(fx >= 0.0 && fy >= 0.0 && fx < n && fy < n)) continue;
        const std::size_t i = static_cast<std::size_t>(fy) * n + static_cast<std::size_t>(fx);
        if (resolved[i] || !centres.launched[i] || counted(c[i])) continue; // traced, or lit and integrated
        resolved[i] = 1;
        queue.push_back({i, darkSub});
    }
    // Light between two edges that crosses no ray: a band between the edges of two apertures, or of
    // one and the counting circle, can be thinner than the grid, lit between all five rays of every
    // cell it crosses and far from other light (docs/sampling-cases.md, "Bands between two edges").
    // Dark cells whose open traces leave room for light between two edges are resolved.
    for (const std::size_t i : cellsWithRoomForLight(L, steps, pupil, field, centres, c, k, maxRadius, resolved)) {
        resolved[i] = 1;
        queue.push_back({i, darkSub});
    }
    while (!queue.empty()) {
        std::vector<optics::Ray> subRays;
        std::vector<std::size_t> first; // each queued cell's first sub-ray
        for (const Resolve& r : queue) {
            const int col = static_cast<int>(r.cell % static_cast<std::size_t>(n)),
                      row = static_cast<int>(r.cell / static_cast<std::size_t>(n));
            const Bundle sub = gridBundle(pupil, field, r.sub, centres.x0 + (col + 0.5) * centres.cell,
                                          centres.y0 + (row + 0.5) * centres.cell, 0.5 * centres.cell, false);
            first.push_back(subRays.size());
            subRays.insert(subRays.end(), sub.rays.begin(), sub.rays.end());
            areas.insert(areas.end(), sub.rays.size(), centres.cellArea / (double(r.sub) * r.sub));
        }
        // Each sub-ray stands for the share of its sub-cell whose light passes (open_trace.h): light
        // counted whole or not at all by sub-cells moves the moments in steps of a sub-row's light
        // wherever an edge runs along the rows (docs/sampling-cases.md, "Edges along the rows").
        std::vector<int> subs;
        for (const Resolve& r : queue) subs.push_back(r.sub);
        const SubGridTrace traced = traceSubGrids(tracer, L, steps, subRays, first, subs, maxRadius);
        const std::vector<double>& share = traced.share;
        const std::size_t base = hits.size();
        for (std::size_t s = 0; s < subRays.size(); ++s) areas[base + s] *= share[s];
        hits.insert(hits.end(), traced.hits.begin(), traced.hits.end());
        std::vector<Resolve> next;
        for (std::size_t q = 0; q < queue.size(); ++q) {
            const int col = static_cast<int>(queue[q].cell % static_cast<std::size_t>(n));
            const int row = static_cast<int>(queue[q].cell / static_cast<std::size_t>(n));
            const int sub = queue[q].sub, last = sub - 1;
            const double* lit = &share[first[q]];
            for (int sj = 0; sj < sub; ++sj)
                for (int si = 0; si < sub; ++si) {
                    if ((si != 0 && si != last && sj != 0 && sj != last) || !(lit[sj * sub + si] > 0.0)) continue;
                    for (int dj = sj == 0 ? -1 : 0; dj <= (sj == last ? 1 : 0); ++dj)
                        for (int di = si == 0 ? -1 : 0; di <= (si == last ? 1 : 0); ++di) {
                            const int nc = col + di, nr = row + dj;
                            if ((di == 0 && dj == 0) || nc < 0 || nr < 0 || nc >= n || nr >= n) continue;
                            const std::size_t j = static_cast<std::size_t>(nr) * n + nc;
                            if (resolved[j] || !centres.launched[j] || counted(c[j])) continue;
                            resolved[j] = 1;
                            next.push_back({j, darkSub});
                        }
                }
        }
        queue = std::move(next);
    }
    // The whole cells integrated above count wholly; the sub-rays' areas hold their shares.
    BundleMoments m = measureSamples(hits, areas, scale, 0.0);
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
