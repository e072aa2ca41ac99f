// `fourierflare table`: build (or fetch from the cache) a lens's ghost table and write it as JSON.

#include "cli/commands.h"
#include "cli/conventions.h"
#include "cli/trace_choices.h"
#include "core/error.h"
#include "core/file_io.h"
#include "ghosts/table_json.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace ff::cli {

namespace {

struct TableCommandOptions {
    std::string lens, output;
    TableOptions table;
    bool noCache = false;
};

void runTable(const TableCommandOptions& o, const GlobalOptions& g) {
    if (samePath(o.output, o.lens))
        throw Error(ErrorKind::Usage, "the output '" + o.output + "' is the input lens file");
    ConsoleReporter reporter(g);
    const optics::Lens lens = loadTraceableLens(o.lens, o.table.zoom, reporter);
    bool cached = false;
    const ghosts::GhostTable t = loadTable(lens, o.table.settings(), g, reporter, !o.noCache, &cached);
    writeFileAtomic(o.output, ghosts::tableToJson(t));

    if (g.quiet) return;
    // Fit quality over every ghost, wavelength and angle with flux (median and worst), each entry
    // weighed by the field it stands for (half of each neighbouring interval).
    std::vector<std::pair<double, double>> ge, ce; // (error, weight)
    for (const auto& gh : t.ghosts) {
        const auto& a = gh.anglesDeg;
        for (const auto& row : gh.entries)
            for (std::size_t i = 0; i < row.size(); ++i) {
                if (row[i].flux <= 0.0) continue;
                const double weight = 0.5 * (a[std::min(i + 1, a.size() - 1)] - a[i == 0 ? 0 : i - 1]);
                ge.emplace_back(row[i].gaussian.error, weight), ce.emplace_back(row[i].cos2.error, weight);
            }
    }
    auto median = [](std::vector<std::pair<double, double>> v) {
        if (v.empty()) return 0.0;
        std::sort(v.begin(), v.end());
        double total = 0.0, below = 0.0;
        for (const auto& e : v) total += e.second;
        for (const auto& e : v)
            if ((below += e.second) >= 0.5 * total) return e.first;
        return v.back().first;
    };
    auto worst = [](const std::vector<std::pair<double, double>>& v) {
        double w = 0.0;
        for (const auto& e : v) w = std::max(w, e.first);
        return w;
    };
    // (How long the build took was said by loadTable.)
    std::fprintf(stderr,
                 "fourierflare: %s table: %zu ghosts x %zu wavelengths at %zu field angles, 0..%.2f deg (every entry "
                 "measured on its ghost's shaped mesh; linear between angles)\n",
                 cached ? "cached" : "built", t.ghosts.size(), t.wavelengthsNm.size(), t.anglesDeg.size(),
                 t.anglesDeg.back());
    std::fprintf(stderr,
                 "fourierflare: fit error (relative L2) over the field: Gaussian median %.3f, worst %.3f; cos2 median "
                 "%.3f, worst %.3f\n",
                 median(ge), worst(ge), median(ce), worst(ce));
    std::fprintf(stderr, "fourierflare: wrote %s\n", o.output.c_str());
}

} // namespace

void addTableCommand(CLI::App& app, GlobalOptions& global) {
    auto o = std::make_shared<TableCommandOptions>();
    CLI::App* cmd =
        app.add_subcommand("table", "Build a lens's ghost table (fitted ghosts over field angle) and write it as JSON");
    addLensArgument(*cmd, o->lens);
    cmd->add_option("-o,--output", o->output, "JSON file to write (the canonical table, docs/ghost-table.md)")
        ->required();
    o->table.addTo(*cmd, true, true, false);
    cmd->add_flag("--no-cache", o->noCache, "Build the table even if a cached one exists, and do not store it");
    cmd->footer("The table is cached under $FF_CACHE_DIR, $XDG_CACHE_HOME/fourierflare or ~/.cache/fourierflare.\n"
                "Example: fourierflare table lenses/double-gauss-50mm-f2.lens -o dg.ghosts.json");
    cmd->callback([o, &global] {
        requireLens(o->lens);
        runTable(*o, global);
    });
}

} // namespace ff::cli
