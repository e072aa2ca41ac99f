#include "cli/trace_choices.h"

#include "cli/conventions.h"
#include "core/error.h"
#include "ghosts/shaped_cache.h"
#include "ghosts/table_cache.h"
#include "optics/lens_loader.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <unistd.h>

namespace ff::cli {

optics::Lens loadTraceableLens(const std::string& file, const std::string& zoom, Reporter& reporter) {
    return optics::loadTraceableLens(file, zoom, &reporter);
}

trace::Sampling samplingFrom(const std::string& s) {
    return trace::samplingNamed(s);
}

trace::SensorPlane sensorFrom(const std::string& s) {
    return trace::sensorPlaneNamed(s);
}

trace::CoatingChoice coatingFrom(const std::string& s) {
    return trace::coatingNamed(s);
}

void TableOptions::addTo(CLI::App& cmd, bool legacyGrid, bool withSensor) {
    cmd.add_option("--table-grid", grid, "Rays per side of each ghost's pupil grid for the ghost table")
        ->check(CLI::Range(4, 512));
    if (legacyGrid) addDeprecated(cmd, "--grid", grid, "--table-grid")->check(CLI::Range(4, 512));
    cmd.add_option("--sampling", sampling, "Pupil sampling: reaim or paraxial-grid")
        ->check(CLI::IsMember({"reaim", "paraxial-grid"}));
    if (withSensor)
        cmd.add_option("--sensor", sensor, "Sensor plane: file (the last thickness) or paraxial (the d line's focus)")
            ->check(CLI::IsMember({"file", "paraxial"}));
    cmd.add_option("--coating", coating, "Coatings: file, none or mgf2")
        ->check(CLI::IsMember({"file", "none", "mgf2"}));
    cmd.add_option("--max-angle", maxAngle,
                   "Largest field angle of the ghost table in degrees (0: the sensor's half-diagonal plus 5 %)")
        ->check(CLI::Range(0.0, 85.0));
    cmd.add_option("--table-angles", maxAngles,
                   "Field angles the ghost table's refinement may trace per ghost, on average (more: finer steps "
                   "where ghosts change fast)")
        ->check(CLI::Range(9, 513));
    addDeprecated(cmd, "--max-angles", maxAngles, "--table-angles")->check(CLI::Range(9, 513));
    cmd.add_option("--tolerance", tolerance,
                   "Interpolation error of centroid and spreads the ghost table's refinement aims at (relative)")
        ->check(CLI::Range(1e-6, 1.0));
    cmd.add_option("--zoom", zoom, "Zoom position (label or 1-based index)");
}

ghosts::TableSettings TableOptions::settings() const {
    return ghosts::TableSettings::named(grid, sampling, sensor, coating, maxAngle, maxAngles, tolerance);
}

ghosts::GhostTable loadTable(const optics::Lens& lens, const TableOptions& table, const GlobalOptions& g,
                             Reporter& reporter, bool useCache, bool* fromCache) {
    const bool bar = !g.quiet && isatty(STDERR_FILENO);
    ghosts::Progress progress;
    if (bar)
        progress = [](std::size_t done, std::size_t total) {
            const int width = 40, filled = static_cast<int>(width * std::min(1.0, double(done) / double(total)));
            std::fprintf(stderr, "\rfourierflare: ghost table [%.*s%*s] %zu", filled,
                         "########################################", width - filled, "", done);
            std::fflush(stderr);
        };
    bool cached = false;
    ghosts::GhostTable t = ghosts::tableFor(lens, table.settings(), useCache, progress, reporter, &cached);
    if (bar) std::fprintf(stderr, "\n");
    if (!g.quiet && !cached) {
        std::fprintf(stderr, "fourierflare: built the ghost table in %.1f s%s\n", t.buildSeconds,
                     useCache ? " (cached for next time)" : "");
        const ghosts::BuildReport& b = t.build;
        std::fprintf(stderr, "fourierflare: %zu traces of a budget of %zu%s in %zu rounds:", b.traces(), b.budget,
                     b.budgetSpent ? " (spent)" : "", b.rounds);
        const char* separator = " ";
        for (const auto& [name, step] : {std::pair{"start", b.start},
                                         {"mid-angles", b.midAngles},
                                         {"neighbours", b.neighbours},
                                         {"carried", b.carried},
                                         {"knots", b.knots},
                                         {"finer grids", b.finer}}) {
            std::fprintf(stderr, "%s%s %zu (%.0f s)", separator, name, step.traces, step.seconds);
            separator = ", ";
        }
        if (b.finerGhosts > 0) std::fprintf(stderr, " for %zu ghost%s", b.finerGhosts, b.finerGhosts == 1 ? "" : "s");
        std::fprintf(stderr, "\n");
        if (!b.worst.ghost.empty())
            std::fprintf(stderr, "fourierflare: the worst interval: %s at %.7f to %.7f deg (%.2f %%)\n",
                         b.worst.ghost.c_str(), b.worst.fromDeg, b.worst.toDeg, 100.0 * b.worst.error);
    }
    if (fromCache) *fromCache = cached;
    return t;
}

ghosts::ShapedTable loadShapedTable(const optics::Lens& lens, const ghosts::ShapedSettings& settings,
                                    const GlobalOptions& g, Reporter& reporter) {
    bool cached = false;
    ghosts::ShapedTable t = ghosts::shapedTableFor(lens, settings, true, reporter, &cached);
    if (!g.quiet && !cached)
        std::fprintf(
            stderr,
            "fourierflare: built the shaped ghosts (%zu of %zu ghosts, %zu rays) in %.1f s (cached for next time)\n",
            t.ghosts.size(), t.ghostCount, t.rays, t.buildSeconds);
    return t;
}

} // namespace ff::cli
