#include "ghosts/instancing.h"

#include <algorithm>
#include <cmath>

namespace ff::ghosts {

double fieldAngleForRadius(const GhostTable& t, double r) {
    const std::size_t g = t.nearestWavelength(550.0);
    double lo = t.anglesDeg.front(), hi = t.anglesDeg.back();
    if (r >= t.directAt(g, hi)) return hi;
    // The direct image height grows with the angle: bisection on the interpolated table.
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (t.directAt(g, mid) < r ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

std::vector<GhostInstance> instantiate(const GhostTable& t, const std::vector<Light>& lights,
                                       const trace::ImageFrame& frame, Profile profile) {
    const std::array<std::size_t, 3> ch = t.rgbChannels();
    const double pitch = frame.pitchMm;
    std::vector<GhostInstance> out;
    for (std::size_t l = 0; l < lights.size(); ++l) {
        const Light& light = lights[l];
        // Sensor position in mm with +y up; the image's y axis points down.
        const glm::dvec2 at = frame.pixelToSensor(light.xPx, light.yPx);
        const double sx = at.x, sy = at.y;
        const double r = std::hypot(sx, sy);
        const double ex = r > 0.0 ? sx / r : 0.0, ey = r > 0.0 ? sy / r : 1.0;
        const double angle = fieldAngleForRadius(t, r);
        for (std::size_t g = 0; g < t.ghosts.size(); ++g) {
            GhostInstance gi;
            gi.ghost = g;
            gi.light = l;
            gi.profile = profile;
            bool any = false;
            for (int c = 0; c < 3; ++c) {
                const TableEntry e = t.at(g, ch[c], angle);
                const ProfileFit& f = profile == Profile::Gaussian ? e.gaussian : e.cos2;
                gi.flux[c] = light.flux[c] * e.flux;
                gi.widthR[c] = f.widthR / pitch;
                gi.widthT[c] = f.widthT / pitch;
                any = any || gi.flux[c] > 0.0;
            }
            if (!any) continue;
            // Centre m r e (green channel), back to pixels.
            const double m = t.magnification(g, ch[1], angle);
            const glm::dvec2 centre = frame.sensorToPixel(m * r * ex, m * r * ey);
            gi.xPx = centre.x;
            gi.yPx = centre.y;
            gi.radialAngle = std::atan2(-ey, ex);
            out.push_back(gi);
        }
    }
    return out;
}

} // namespace ff::ghosts
