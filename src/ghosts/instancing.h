#pragma once
// Ghost instances for any set of lights: a table lookup per light and ghost, no tracing.
//
// A light at image position p (pixels -> sensor mm through the image frame) lies at distance r from the
// optical centre in direction e = p / r. Its field angle is the one whose traced direct image height
// (from the table, distortion included) equals r. Each ghost is the table entry at that angle rotated
// onto e: centre m r e, widths along e (radial) and across it (tangential), flux = the light's flux x
// the ghost's relative flux per channel.

#include "ghosts/table_data.h"
#include "trace/flare_raster.h"

#include <array>
#include <vector>

namespace ff::ghosts {

struct Light {
    double xPx = 0.0, yPx = 0.0;         ///< image position, pixels (origin top-left, +y down)
    std::array<double, 3> flux{1, 1, 1}; ///< RGB flux of the light's direct image
};

struct GhostInstance {
    std::size_t ghost = 0, light = 0; ///< indices into the table's ghosts and the lights
    double xPx = 0.0, yPx = 0.0;      ///< centre, pixels
    double radialAngle = 0.0;         ///< direction of the radial axis in the image, radians from +x (image y down)
    std::array<double, 3> widthR{}, widthT{}; ///< profile widths per channel, pixels (sigma or cos^2 w)
    std::array<double, 3> flux{};             ///< RGB flux
    Profile profile = Profile::Gaussian;
};

/// Field angle (degrees) whose direct image (green channel) lies rMm from the centre; the table's
/// largest angle if r is beyond it.
double fieldAngleForRadius(const GhostTable& table, double rMm);

/// Instances of every ghost with non-zero flux for every light. Channels are the table wavelengths
/// nearest to 650 / 550 / 450 nm.
std::vector<GhostInstance> instantiate(const GhostTable& table, const std::vector<Light>& lights,
                                       const trace::ImageFrame& frame, Profile profile = Profile::Gaussian);

} // namespace ff::ghosts
