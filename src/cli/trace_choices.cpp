#include "cli/trace_choices.h"

#include "cli/conventions.h"
#include "core/error.h"
#include "ghosts/shaped_cache.h"
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

void TableOptions::addTo(CLI::App& cmd, bool legacyGrid, bool withSensor, bool traced) {
    cmd.add_option("--table-grid", grid,
                   "Cells per side of the table's pupil mesh for its most concentrated ghost (the others get fewer, "
                   "at least 16)")
        ->check(CLI::Range(4, 512));
    if (legacyGrid) addDeprecated(cmd, "--grid", grid, "--table-grid")->check(CLI::Range(4, 512));
    cmd.add_option("--table-angles", angles, "Field angles of the table, uniform from 0 to --max-angle")
        ->check(CLI::Range(2, 1024));
    if (traced)
        cmd.add_option("--sampling", sampling, "Pupil sampling of the traced paths: reaim or paraxial-grid")
            ->check(CLI::IsMember({"reaim", "paraxial-grid"}));
    else
        addRetired(cmd, "--sampling", "the table's meshes cover each ghost's light wherever it is");
    addRetired(cmd, "--tolerance", "the table's angles are uniform; give --table-angles");
    addRetired(cmd, "--max-angles", "the table's angles are uniform; give --table-angles");
    if (withSensor)
        cmd.add_option("--sensor", sensor, "Sensor plane: file (the last thickness) or paraxial (the d line's focus)")
            ->check(CLI::IsMember({"file", "paraxial"}));
    cmd.add_option("--coating", coating, "Coatings: file, none or mgf2")
        ->check(CLI::IsMember({"file", "none", "mgf2"}));
    cmd.add_option("--max-angle", maxAngle,
                   "Largest field angle of the ghost table in degrees (0: the sensor's half-diagonal plus 5 %)")
        ->check(CLI::Range(0.0, 85.0));
    cmd.add_option("--zoom", zoom, "Zoom position (label or 1-based index)");
}

ghosts::TableSettings TableOptions::settings() const {
    return ghosts::TableSettings::named(grid, angles, sensor, coating, maxAngle);
}

ghosts::GhostTable loadTable(const optics::Lens& lens, const ghosts::TableSettings& settings, const GlobalOptions& g,
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
    ghosts::GhostTable t = ghosts::tableFor(lens, settings, useCache, progress, reporter, &cached);
    if (bar) std::fprintf(stderr, "\n");
    if (!g.quiet && !cached) {
        std::fprintf(stderr, "fourierflare: built the table (shaped ghosts and their fits) in %.1f s%s\n",
                     t.buildSeconds, useCache ? " (cached for next time)" : "");
    }
    if (fromCache) *fromCache = cached;
    return t;
}

ghosts::ShapedTable loadShapedTable(const optics::Lens& lens, const ghosts::TableSettings& settings,
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
