// `fourierflare lens info` and `fourierflare lens convert`.

#include "cli/commands.h"
#include "cli/conventions.h"
#include "cli/lens_report.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_writer.h"
#include "optics/real_ray.h"
#include "optics/zoom.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>

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
    std::vector<std::size_t> which;
    if (!o.zoom.empty())
        which.push_back(optics::findZoomPosition(lens, o.zoom));
    else
        for (std::size_t k = 0; k < lens.zoomCount(); ++k) which.push_back(k);

    std::vector<PositionReport> positions;
    for (std::size_t k : which) {
        const optics::Lens at = optics::atZoom(lens, k);
        PositionReport p;
        p.label = lens.isZoom() ? lens.zoomLabels[k] : std::string();
        p.firstOrder = optics::analyzeFirstOrder(at, o.lambdaNm, /*allowAfocal=*/true);
        if (p.firstOrder.afocal) {
            p.realRayEfl = std::numeric_limits<double>::quiet_NaN();
            p.realRayProblem = "the lens is afocal: a ray parallel to the axis leaves parallel";
        } else
            try {
                p.realRayEfl = optics::realRayEfl(at, o.lambdaNm, 1e-4 * 0.5 * p.firstOrder.entrancePupilDiameter);
            } catch (const Error& e) {
                // A check of the paraxial data, not part of them: the report goes on without it.
                p.realRayEfl = std::numeric_limits<double>::quiet_NaN();
                p.realRayProblem = e.message();
                reporter.note({lens.file, 0, 0}, "the real-ray focal length could not be checked: " + p.realRayProblem);
            }
        positions.push_back(p);
    }
    if (o.json)
        std::cout << lensInfoJson(lens, o.lambdaNm, positions).dump(2) << "\n";
    else
        std::cout << lensInfoText(lens, o.lambdaNm, positions);
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
