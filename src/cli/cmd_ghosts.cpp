// `fourierflare ghosts`: the ghost report of a lens at one field angle.

#include "cli/commands.h"
#include "cli/conventions.h"
#include "cli/option_parsing.h"
#include "cli/trace_choices.h"
#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "trace/ghost_analysis.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <tuple>

#include "report/ghost_report.h"

namespace ff::cli {

namespace {

struct GhostsOptions {
    std::string file;
    std::string angle;                ///< "DEG[,AZ]"
    double angleDeg = 0.0;            ///< from angle
    double azimuthDeg = 0.0;          ///< from angle, or the deprecated --azimuth
    std::optional<double> oldAzimuth; ///< --azimuth (deprecated)
    std::vector<double> wavelengths = {550.0};
    std::string coating = "file";
    std::string sampling = "reaim";
    int grid = 64;
    std::string sensor = "file";
    int top = 0;
    bool json = false;
    std::string zoom;
};

// Pads to a display width counted in UTF-8 code points (labels contain the arrow U+2192).
std::string padRight(const std::string& s, std::size_t width) {
    std::size_t points = 0;
    for (unsigned char c : s) points += (c & 0xC0) != 0x80;
    return points >= width ? s : s + std::string(width - points, ' ');
}

// Avoids printing "-0.000" for values that round to zero.
double tidy(double v) {
    return std::abs(v) < 5e-4 ? 0.0 : v;
}

void printPath(const trace::PathStats& p, std::size_t rank) {
    char ratio[32];
    if (std::isfinite(p.axialRatio))
        std::snprintf(ratio, sizeof ratio, "%8.3f", p.axialRatio);
    else
        std::snprintf(ratio, sizeof ratio, "%8s", "n/a");
    std::printf("  %4zu  %s %8zu %9zu %8.3f  %11.4e %11.4e  %9.3f %9.3f  %9.3f  %s  %8.3f\n", rank,
                padRight(p.label(), 10).c_str(), p.launched, p.surviving,
                p.launched ? double(p.surviving) / double(p.launched) : 0.0, p.relativeEnergy, p.energyPerRay,
                tidy(p.centroidX), tidy(p.centroidY), p.rmsRadius, ratio, p.onSensor);
}

void runGhosts(const GhostsOptions& o, const GlobalOptions& g) {
    ConsoleReporter reporter(g);
    const optics::Lens lens = loadTraceableLens(o.file, o.zoom, reporter);
    report::GhostQuery q;
    q.angleDeg = o.angleDeg;
    q.azimuthDeg = o.azimuthDeg;
    q.wavelengthsNm = o.wavelengths;
    q.grid = o.grid;
    q.sampling = o.sampling;
    q.sensor = o.sensor;
    q.coating = o.coating;
    const trace::GhostReport r = trace::analyzeGhosts(lens, q.options());
    const std::size_t nGhosts = r.wavelengths.empty() ? 0 : r.wavelengths[0].ghosts.size();
    const std::size_t shown = o.top > 0 ? std::min<std::size_t>(static_cast<std::size_t>(o.top), nGhosts) : nGhosts;

    if (o.json) {
        std::cout << report::ghostReportJson(lens, q, r, shown).dump(2) << "\n";
        return;
    }
    std::printf("Ghosts of %s at %.2f deg (azimuth %.1f deg)\n", lens.name.c_str(), o.angleDeg, o.azimuthDeg);
    std::printf(
        "  sensor plane %.3f mm behind the first vertex (%s), sensor %gx%g mm; sampling %s, grid %dx%d; coating %s\n",
        r.sensorZ, o.sensor.c_str(), r.sensorSizeMm.first, r.sensorSizeMm.second, o.sampling.c_str(), o.grid, o.grid,
        o.coating.c_str());
    std::printf("  %zu reflecting interfaces -> %zu two-bounce ghosts%s\n", r.reflectingInterfaces, nGhosts,
                shown < nGhosts ? (", the " + std::to_string(shown) + " strongest shown").c_str() : "");
    for (const auto& w : r.wavelengths) {
        std::printf("\n%.1f nm\n", w.lambdaNm);
        std::printf("  %4s  %-10s %8s %9s %8s  %11s %11s  %9s %9s  %9s  %8s  %8s\n", "rank", "path", "launched",
                    "surviving", "fraction", "rel.energy", "energy/ray", "x (mm)", "y (mm)", "RMS r", "axial",
                    "on sensor");
        printPath(w.direct, 0);
        for (std::size_t i = 0; i < shown; ++i) printPath(w.ghosts[i], i + 1);
        std::printf("  total ghost energy / direct energy: %.4e (%.3f %%)\n", w.totalGhostRelative,
                    100.0 * w.totalGhostRelative);
    }
}

} // namespace

void addGhostsCommand(CLI::App& app, GlobalOptions& global) {
    auto o = std::make_shared<GhostsOptions>();
    CLI::App* cmd = app.add_subcommand(
        "ghosts", "Trace the direct image and every two-bounce ghost at one field angle and report them");
    addLensArgument(*cmd, o->file);
    cmd->add_option("--angle", o->angle,
                    "Field angle of the source in degrees, optionally with its azimuth: DEG[,AZ] (0: the direct "
                    "image at +y; counter-clockwise)")
        ->required();
    addDeprecated(*cmd, "--azimuth", o->oldAzimuth, "--angle DEG,AZ");
    cmd->add_option("--wavelength", o->wavelengths, "Wavelength(s) in nm (repeat the option for several)")
        ->check(CLI::Range(300.0, 2000.0));
    cmd->add_option("--coating", o->coating,
                    "Coatings: file (as the lens says), none, or mgf2 (single quarter wave at 550 nm)")
        ->check(CLI::IsMember({"file", "none", "mgf2"}));
    cmd->add_option("--sampling", o->sampling, "Pupil sampling: reaim (each path's real pupil) or paraxial-grid")
        ->check(CLI::IsMember({"reaim", "paraxial-grid"}));
    cmd->add_option("--grid", o->grid, "Rays per side of the pupil grid")->check(CLI::Range(2, 1024));
    cmd->add_option("--sensor", o->sensor,
                    "Sensor plane: file (the last thickness) or paraxial (paraxial focus at the d line)")
        ->check(CLI::IsMember({"file", "paraxial"}));
    cmd->add_option("--top", o->top, "Show only the K strongest ghosts (0: all)")->check(CLI::Range(0, 100000));
    cmd->add_option("--zoom", o->zoom, "Zoom position (label or 1-based index)");
    cmd->add_flag("--json", o->json, "Print JSON instead of text");
    cmd->footer(
        "Example: fourierflare ghosts lenses/double-gauss-50mm-f2.lens --angle 10 --wavelength 550 --coating none "
        "--sampling paraxial-grid --grid 64 --sensor paraxial --json");
    cmd->callback([o, &global] {
        requireLens(o->file);
        std::tie(o->angleDeg, o->azimuthDeg) = parseAngle(o->angle, "--angle");
        if (o->oldAzimuth) {
            if (o->angle.find(',') != std::string::npos)
                throw Error(ErrorKind::Usage, "give the azimuth once: --angle DEG,AZ (--azimuth is its old spelling)");
            o->azimuthDeg = *o->oldAzimuth;
        }
        runGhosts(*o, global);
    });
}

} // namespace ff::cli
