// `fourierflare lens info` and `fourierflare lens convert`.

#include "cli/commands.h"
#include "cli/conventions.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_writer.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>

#include "report/lens_report.h"

namespace ff::cli {

namespace {

struct InfoOptions {
    std::string file;
    double lambdaNm = lines::d;
    bool json = false;
    std::string zoom;
};

struct ConvertOptions {
    std::string input, output;
};

void runInfo(const InfoOptions& o, const GlobalOptions& g) {
    ConsoleReporter reporter(g);
    const optics::Lens lens = optics::loadLens(o.file, &reporter);
    const std::vector<report::PositionReport> positions = report::positionReports(lens, o.lambdaNm, o.zoom, &reporter);
    if (o.json)
        std::cout << report::lensInfoJson(lens, o.lambdaNm, positions).dump(2) << "\n";
    else
        std::cout << report::lensInfoText(lens, o.lambdaNm, positions);
}

void runConvert(const ConvertOptions& o, const GlobalOptions& g) {
    if (samePath(o.input, o.output))
        throw Error(ErrorKind::Usage,
                    "the output '" + o.output + "' is the input file; refusing to overwrite an input");
    ConsoleReporter reporter(g);
    const optics::Lens lens = optics::loadLens(o.input, &reporter);
    writeFileAtomic(o.output, optics::writeLensText(lens));
    if (!g.quiet)
        std::fprintf(stderr, "fourierflare: wrote %s (%zu surfaces)\n", o.output.c_str(), lens.surfaces.size());
}

} // namespace

void addLensCommand(CLI::App& app, GlobalOptions& global) {
    CLI::App* lens = app.add_subcommand("lens", "Inspect and convert lens prescriptions (.lens, .zmx, .dat)");
    lens->require_subcommand(1);

    auto info = std::make_shared<InfoOptions>();
    CLI::App* infoCmd = lens->add_subcommand(
        "info", "Print a lens's surfaces and first-order optics (EFL, BFD, pupils, f-number, ghosts)");
    addLensArgument(*infoCmd, info->file);
    infoCmd
        ->add_option("-w,--wavelength", info->lambdaNm, "Wavelength in nm for the first-order data (default: d line)")
        ->capture_default_str()
        ->check(CLI::Range(300.0, 2000.0));
    infoCmd->add_flag("--json", info->json, "Print JSON instead of text");
    infoCmd->add_option("--zoom", info->zoom, "Only this zoom position (label or 1-based index; default: all)");
    infoCmd->footer("Example: fourierflare lens info lenses/double-gauss-50mm-f2.lens --wavelength 550");
    infoCmd->callback([info, &global] {
        requireLens(info->file);
        runInfo(*info, global);
    });

    auto conv = std::make_shared<ConvertOptions>();
    CLI::App* convCmd =
        lens->add_subcommand("convert", "Convert a lens file (.zmx, .dat, .lens) to the native .lens format");
    addLensArgument(*convCmd, conv->input, "Lens file to read (.zmx, .dat or .lens)");
    convCmd->add_option("-o,--output", conv->output, "Native .lens file to write (never the input)")->required();
    convCmd->footer("Example: fourierflare lens convert dgauss.50mm.dat -o dgauss.lens");
    convCmd->callback([conv, &global] {
        requireLens(conv->input);
        runConvert(*conv, global);
    });
}

} // namespace ff::cli
