#pragma once
// What the tracing commands (ghosts, render) share: reading a lens they can trace and turning the
// option strings into the tracer's choices. The strings are validated by CLI11 beforehand.

#include "cli/console.h"
#include "ghosts/ghost_table.h"
#include "ghosts/shaped_ghosts.h"
#include "optics/lens.h"
#include "trace/ghost_analysis.h"

#include <string>

namespace CLI {
class App;
}

namespace ff::cli {

/// Loads the lens at the given zoom position ("" = the first) and refuses anamorphic lenses.
optics::Lens loadTraceableLens(const std::string& file, const std::string& zoom, Reporter& reporter);

trace::Sampling samplingFrom(const std::string& s);     ///< reaim | paraxial-grid
trace::SensorPlane sensorFrom(const std::string& s);    ///< file | paraxial
trace::CoatingChoice coatingFrom(const std::string& s); ///< file | none | mgf2

/// The options that decide the table (the shaped ghosts and their fits), shared by every command that
/// builds one (table, export, render, compare, simulate), so that the same values find the same cache
/// entry; and the traced paths' pupil sampling, which the table does not use.
struct TableOptions {
    int grid = ghosts::TableSettings{}.grid;
    int angles = ghosts::TableSettings{}.angles;
    std::string sampling = "reaim", sensor = "file", coating = "file";
    double maxAngle = 0.0;
    std::string zoom;

    /// --table-grid, --table-angles, --sampling (where the command traces paths: traced), --sensor (the
    /// plane; unless !withSensor), --coating, --max-angle, --zoom. legacyGrid: also --grid for the
    /// table's grid (table and export, which have no traced grid), deprecated. The refined moment
    /// table's --tolerance and --max-angles (and --sampling where nothing is traced) are retired.
    void addTo(CLI::App& cmd, bool legacyGrid = false, bool withSensor = true, bool traced = true);
    ghosts::TableSettings settings() const;
};

/// The ghost table of the lens: from the cache when a valid entry exists (and useCache), else built
/// with a progress bar on a terminal, saying how long it took; `fromCache` tells which happened.
ghosts::GhostTable loadTable(const optics::Lens& lens, const ghosts::TableSettings& settings, const GlobalOptions& g,
                             Reporter& reporter, bool useCache = true, bool* fromCache = nullptr);

/// The lens's shaped ghosts from the cache, else built and stored, saying so with the time, size and
/// ghosts kept (unless -q).
ghosts::ShapedTable loadShapedTable(const optics::Lens& lens, const ghosts::TableSettings& settings,
                                    const GlobalOptions& g, Reporter& reporter);

} // namespace ff::cli
