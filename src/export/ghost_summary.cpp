#include "export/ghost_summary.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ff::exporting {

double defaultFieldAngle(const ghosts::GhostTable& t) {
    return t.anglesDeg.empty() ? 0.0 : 0.5 * t.anglesDeg.back();
}

std::vector<GhostSummary> summarize(const ghosts::GhostTable& t, double angle, std::size_t top) {
    const std::array<std::size_t, 3> channel = t.rgbChannels();
    std::vector<GhostSummary> out;
    for (std::size_t g = 0; g < t.ghosts.size(); ++g) {
        GhostSummary s;
        const auto& pair = t.ghosts[g].pair;
        s.surfaceJ = pair.first + 1;
        s.surfaceI = pair.second + 1;
        s.id = "g_" + std::to_string(s.surfaceJ) + "_" + std::to_string(s.surfaceI);
        s.label = pair.label();
        for (int c = 0; c < 3; ++c) s.flux[c] = t.at(g, channel[c], angle).flux;
        s.meanFlux = (s.flux[0] + s.flux[1] + s.flux[2]) / 3.0;
        if (s.meanFlux <= 0.0) continue;
        const double peak = std::max({s.flux[0], s.flux[1], s.flux[2]});
        for (int c = 0; c < 3; ++c) s.tint[c] = s.flux[c] / peak;
        const ghosts::TableEntry green = t.at(g, channel[1], angle);
        s.magnification = t.magnification(g, channel[1], angle);
        s.radiusMm = 0.5 * (green.cos2.widthR + green.cos2.widthT);
        s.gaussianSigmaR = green.gaussian.widthR;
        s.gaussianSigmaT = green.gaussian.widthT;
        s.gaussianError = green.gaussian.error;
        s.cos2WR = green.cos2.widthR;
        s.cos2WT = green.cos2.widthT;
        s.cos2Error = green.cos2.error;
        s.survivingFraction = green.surviving;
        s.surfaceBrightness = s.radiusMm > 0.0 ? s.meanFlux / (std::numbers::pi * s.radiusMm * s.radiusMm) : 0.0;
        out.push_back(s);
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const GhostSummary& a, const GhostSummary& b) { return a.meanFlux > b.meanFlux; });
    if (top > 0 && out.size() > top) out.resize(top);
    double brightest = 0.0;
    for (const auto& s : out) brightest = std::max(brightest, s.surfaceBrightness);
    for (auto& s : out) s.surfaceBrightness = brightest > 0.0 ? s.surfaceBrightness / brightest : 0.0;
    return out;
}

} // namespace ff::exporting
