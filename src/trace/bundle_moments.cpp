#include "trace/bundle_moments.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ff::trace {

BundleMoments measureBundle(const Bundle& b, const std::vector<RayResult>& hits, double scale, double maxRadius) {
    std::vector<double> areas(hits.size());
    for (std::size_t i = 0; i < hits.size(); ++i) areas[i] = b.launched[i] ? b.cellArea : 0.0;
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

} // namespace ff::trace
