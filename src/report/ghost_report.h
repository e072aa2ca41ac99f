#pragma once
// The ghost report (`fourierflare ghosts --json`, the Python module's ghost_report) as JSON: what was
// asked, then per wavelength the direct image and the ghosts, strongest first (mm on the sensor,
// energies relative to the direct image's).

#include "optics/lens.h"
#include "trace/ghost_analysis.h"

#include <nlohmann/json_fwd.hpp>

#include <string>
#include <vector>

namespace ff::report {

/// A ghost report's request, as given (degrees, nanometres, the choices' names).
struct GhostQuery {
    double angleDeg = 0.0, azimuthDeg = 0.0;
    std::vector<double> wavelengthsNm = {550.0};
    std::string sampling = "reaim", sensor = "file", coating = "file";
    int grid = 64;

    /// The tracer's options (throws ff::Error, Usage, for an unknown name or a grid outside 2..4096).
    trace::GhostAnalysisOptions options() const;
};

/// One path's statistics ("path", "launched", ..., "surfaces" 1-based for a ghost).
nlohmann::json pathJson(const trace::PathStats& p);

/// The whole report, with the `shown` strongest ghosts of each wavelength (all: the ghost count).
nlohmann::json ghostReportJson(const optics::Lens& lens, const GhostQuery& query, const trace::GhostReport& report,
                               std::size_t shown);

} // namespace ff::report
