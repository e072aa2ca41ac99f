#pragma once
// One line per ghost at a reference field angle: what the engine exports need, read from a ghost
// table. Colour channels come from the table wavelengths nearest to 650 / 550 / 450 nm.

#include "ghosts/ghost_table.h"

#include <array>
#include <string>
#include <vector>

namespace ff::exporting {

struct GhostSummary {
    std::string id;    ///< g_<j>_<i>, 1-based surfaces in the order the light meets them
    std::string label; ///< R<j>→R<i>
    std::size_t surfaceJ = 0, surfaceI = 0;
    double magnification = 0.0;     ///< ghost centre = m x direct image position (green channel)
    double radiusMm = 0.0;          ///< mean cos^2 half-width (green): where the ghost's disc ends
    std::array<double, 3> flux{};   ///< R, G, B flux relative to the direct image
    std::array<double, 3> tint{};   ///< flux normalised so the largest channel is 1
    double meanFlux = 0.0;          ///< (R + G + B) / 3
    double surfaceBrightness = 0.0; ///< mean flux / (pi radius^2), relative to the brightest ghost's
    double gaussianSigmaR = 0.0, gaussianSigmaT = 0.0, gaussianError = 0.0;
    double cos2WR = 0.0, cos2WT = 0.0, cos2Error = 0.0;
    double survivingFraction = 0.0;
};

/// The ghosts at fieldAngleDeg, strongest (mean flux) first, at most `top` of them (0 = all);
/// ghosts carrying no light at that angle are left out.
std::vector<GhostSummary> summarize(const ghosts::GhostTable& table, double fieldAngleDeg, std::size_t top = 0);

/// The reference angle used when none is given: half the table's largest field angle.
double defaultFieldAngle(const ghosts::GhostTable& table);

} // namespace ff::exporting
