#pragma once
// Presentation of `fourierflare lens info`: the surface table and first-order data as aligned text
// for people, or as JSON for scripts (every number in mm / nm, full precision).

#include "optics/lens.h"
#include "optics/paraxial.h"

#include <nlohmann/json_fwd.hpp>

#include <string>
#include <vector>

namespace ff::cli {

/// First-order data of one zoom position (label empty for a prime lens).
struct PositionReport {
    std::string label;
    optics::FirstOrder firstOrder;
    double realRayEfl = 0.0;    ///< EFL from a real ray at 1e-4 of the entrance-pupil radius (NaN: not checked)
    std::string realRayProblem; ///< why the real ray could not be traced, where it could not
};

std::string lensInfoText(const optics::Lens& lens, double lambdaNm, const std::vector<PositionReport>& positions);
nlohmann::json lensInfoJson(const optics::Lens& lens, double lambdaNm, const std::vector<PositionReport>& positions);

} // namespace ff::cli
