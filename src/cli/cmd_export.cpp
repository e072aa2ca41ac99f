// `fourierflare export`: a lens's ghost table for game engines (json, csv, unity, unreal, godot).

#include "cli/commands.h"
#include "cli/conventions.h"
#include "cli/trace_choices.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/text.h"
#include "export/engine_exports.h"
#include "export/godot_project.h"
#include "ghosts/table_json.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

namespace ff::cli {

namespace {

struct ExportOptions {
    std::string lens, output, format = "json";
    double fieldAngle = std::numeric_limits<double>::quiet_NaN();
    int top = 0;
    TableOptions table;
};

void runExport(const ExportOptions& o, const GlobalOptions& g) {
    if (samePath(o.output, o.lens))
        throw Error(ErrorKind::Usage, "the output '" + o.output + "' is the input lens file");
    const bool folder = o.format == "godot";
    if (folder && !replaceableFolder(o.output, exporting::kGodotMarker))
        throw Error(ErrorKind::Usage, "--format godot writes a project folder: '" + o.output +
                                          "' exists and is not an empty folder or an earlier Godot export");
    ConsoleReporter reporter(g);
    const optics::Lens lens = loadTraceableLens(o.lens, o.table.zoom, reporter);
    bool cached = false;
    const ghosts::GhostTable t = loadTable(lens, o.table.settings(), g, reporter, true, &cached);
    const double angle = std::isnan(o.fieldAngle) ? exporting::defaultFieldAngle(t) : o.fieldAngle;
    if (angle < 0.0 || angle > t.anglesDeg.back())
        throw Error(ErrorKind::Usage, "--field-angle " + text::roundTrip(angle) + " is outside the table's 0.." +
                                          text::fixed(t.anglesDeg.back(), 2) + " deg");
    const std::size_t top = static_cast<std::size_t>(o.top);
    std::string content;
    if (folder)
        writeFolderAtomic(o.output, exporting::godotProject(t));
    else if (o.format == "json")
        content = ghosts::tableToJson(t);
    else if (o.format == "csv")
        content = exporting::toCsv(t, angle, top);
    else if (o.format == "unity") {
        std::string name = std::filesystem::path(o.output).stem().string();
        if (name.empty()) name = "FourierFlareGhosts";
        content = exporting::toUnityAsset(t, angle, top, name);
    } else
        content = exporting::toUnrealPreset(t, angle);
    if (!folder) writeFileAtomic(o.output, content);
    const std::string angles = o.format == "json" || folder ? "every field angle of the table"
                                                            : "field angle " + text::fixed(angle, 2) + " deg";
    if (!g.quiet)
        std::fprintf(stderr, "fourierflare: wrote %s (%s, %zu ghosts, %s; table %s)\n", o.output.c_str(),
                     o.format.c_str(), t.ghosts.size(), angles.c_str(), cached ? "from the cache" : "built");
}

} // namespace

void addExportCommand(CLI::App& app, GlobalOptions& global) {
    auto o = std::make_shared<ExportOptions>();
    CLI::App* cmd =
        app.add_subcommand("export", "Export a lens's ghosts for game engines (json, csv, unity, unreal, godot)");
    addLensArgument(*cmd, o->lens);
    cmd->add_option("--format", o->format,
                    "json (the full table), csv (Unreal DataTable), unity (LensFlareDataSRP .asset), unreal "
                    "(LensFlareTints preset), godot (a Godot 3 project folder: the whole table and a shader that "
                    "draws it)")
        ->check(CLI::IsMember({"json", "csv", "unity", "unreal", "godot"}));
    cmd->add_option("-o,--output", o->output, "File to write (godot: the project folder)")->required();
    cmd->add_option("--angle", o->fieldAngle,
                    "Reference field angle in degrees for csv/unity/unreal (default: half the table's range)");
    addDeprecated(*cmd, "--field-angle", o->fieldAngle, "--angle");
    cmd->add_option("--top", o->top, "Only the K strongest ghosts (csv, unity; 0 = all; unreal always takes 8)")
        ->check(CLI::Range(0, 100000));
    o->table.addTo(*cmd, true, true, false);
    cmd->footer("The ghost table comes from the cache when it is there (see 'fourierflare table').\n"
                "Example: fourierflare export lenses/double-gauss-50mm-f2.lens --format unity -o dg.asset\n"
                "         fourierflare export lenses/double-gauss-50mm-f2.lens --format godot -o dg-godot");
    cmd->callback([o, &global] {
        requireLens(o->lens);
        runExport(*o, global);
    });
}

} // namespace ff::cli
