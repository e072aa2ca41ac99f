#pragma once
// The lens report (`fourierflare lens info`, the Python module's Lens): the surface table and
// first-order data as aligned text for people, or as JSON for scripts (every number in mm / nm, full
// precision).

#include "core/reporter.h"
#include "optics/lens.h"
#include "optics/paraxial.h"

#include <nlohmann/json_fwd.hpp>

#include <optional>
#include <string>
#include <vector>

namespace ff::report {

/// First-order data of one zoom position (label empty for a prime lens).
struct PositionReport {
    std::string label;
    optics::FirstOrder firstOrder;
    double realRayEfl = 0.0;    ///< EFL from a real ray at 1e-4 of the entrance-pupil radius (NaN: not checked)
    std::string realRayProblem; ///< why the real ray could not be traced, where it could not
    /// An anamorphic lens: firstOrder and realRayEfl are its y-z section's, these the x-z section's,
    /// and squeeze = EFL y / EFL x (NaN where either is afocal).
    std::optional<optics::FirstOrder> sectionX;
    double realRayEflX = 0.0;
    std::string realRayProblemX;
    double squeeze = 0.0;
};

/// The first-order data of the lens as given (one zoom position) at lambdaNm, afocal lenses included;
/// the real-ray check's failure is kept in realRayProblem and noted to `reporter` (when given).
PositionReport positionReport(const optics::Lens& lens, double lambdaNm, const std::string& label,
                              Reporter* reporter = nullptr);

/// Every zoom position of the lens (or the one `zoom` names: a label or 1-based index).
std::vector<PositionReport> positionReports(const optics::Lens& lens, double lambdaNm, const std::string& zoom = "",
                                            Reporter* reporter = nullptr);

/// One position's first-order data as JSON (the "positions" entries of lensInfoJson).
nlohmann::json positionJson(const PositionReport& p);
/// The surfaces as JSON (lensInfoJson's "surfaces"), indices at lambdaNm.
nlohmann::json surfacesJson(const optics::Lens& lens, double lambdaNm);

std::string lensInfoText(const optics::Lens& lens, double lambdaNm, const std::vector<PositionReport>& positions);
nlohmann::json lensInfoJson(const optics::Lens& lens, double lambdaNm, const std::vector<PositionReport>& positions);

} // namespace ff::report
