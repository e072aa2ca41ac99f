#pragma once
// Energy, centroid and second moments of a traced bundle on the sensor, as the ghost report measures
// a path's light.

#include "trace/embree_tracer.h"
#include "trace/pupil_sampling.h"

#include <vector>

namespace ff::trace {

struct BundleMoments {
    std::size_t launched = 0, surviving = 0, blocked = 0; ///< ray counts over launched rays
    double energy = 0.0;                                  ///< sum of weight x cell area x scale over the counted rays
    double centroidX = 0.0, centroidY = 0.0;              ///< energy-weighted, mm
    double mxx = 0.0, myy = 0.0, mxy = 0.0;               ///< central second moments, mm^2
};

/// Measures the surviving rays; when maxRadiusMm > 0 only those landing within it of the axis count
/// towards energy and moments (the counts still cover every surviving ray).
BundleMoments measureBundle(const Bundle& bundle, const std::vector<RayResult>& hits, double scale = 1.0,
                            double maxRadiusMm = 0.0);

} // namespace ff::trace
