// `fourierflare compare`: the options, the lights (given, or found in a plate) and the report folder
// around scene::compareFlares, the traced flare of a scene against the shaped ghosts and the fitted
// profiles drawn directly and aggregated through Fourier (docs/compare.md).

#include "cli/commands.h"
#include "cli/conventions.h"
#include "cli/fourier_choices.h"
#include "cli/option_parsing.h"
#include "core/error.h"
#include "core/text.h"
#include "gpu/backend_choice.h"
#include "image/light_detection.h"
#include "image/metrics.h"
#include "image/plate.h"
#include "scene/comparison.h"
#include "scene/scene.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

namespace ff::cli {

namespace {

struct CompareOptions {
    std::string lens;
    std::vector<std::string> lights;
    std::string lightsFile, plate;
    std::string threshold = "2";
    int maxLights = 16;
    std::string size;
    std::string ns = "16,32,64,128,256";
    std::string output;
    int grid = 32;
    std::string sensorSize;
    TableOptions table; ///< the ghost table's; its sampling, sensor plane and coatings serve the traced reference too
    std::string diffraction = "off"; ///< off, physical or traced (then the aberration-free one too)
    FourierOptions fourier;
};

// The lights of --plate: found as simulate finds them, the strongest o.maxLights kept (the traced
// reference costs seconds per light), positions scaled to --size. `size` gets the plate's size where
// --size is not given; `found` the number of lights the plate holds.
std::vector<ghosts::Light> plateLights(const CompareOptions& o, std::string& size, std::size_t& found) {
    std::vector<ghosts::Light> lights;
    image::PlateLimits limits;
    limits.checker = image::kThisProgram;
    limits.cpuSeconds = image::plateCheckSeconds();
    const image::Plate plate = image::readPlate(o.plate, limits);
    image::DetectionSettings detection = image::parseThreshold(o.threshold);
    const image::DetectionReport report = image::detectLights(plate, detection);
    found = report.lights.size();
    for (const auto& l : report.lights) lights.push_back({l.x, l.y, l.flux});
    std::stable_sort(lights.begin(), lights.end(), [](const ghosts::Light& a, const ghosts::Light& b) {
        return image::luminance(a.flux[0], a.flux[1], a.flux[2]) > image::luminance(b.flux[0], b.flux[1], b.flux[2]);
    });
    if (lights.size() > static_cast<std::size_t>(o.maxLights)) lights.resize(static_cast<std::size_t>(o.maxLights));
    if (lights.empty())
        throw Error(ErrorKind::Input, SourceLocation{o.plate},
                    "no light above the threshold (luminance " + text::fixed(report.threshold, 3) + ") to compare");
    if (size.empty()) {
        size = std::to_string(plate.displayWidth) + "x" + std::to_string(plate.displayHeight);
    } else {
        // Positions scale with the frame (the frame spans the sensor width); fluxes do not.
        const double scale = double(parseFrameSize(size, "--size", 8, 8192).first) / plate.displayWidth;
        for (auto& l : lights) l.xPx *= scale, l.yPx *= scale;
    }
    return lights;
}

// --fourier-n-sweep: whole numbers 1..2048, sorted.
std::vector<int> parseSweep(const std::string& list) {
    std::vector<int> ns;
    for (auto p : text::split(list, ',')) {
        const auto v = text::parseNumber(p);
        if (!v || *v < 1 || *v > 2048 || *v != std::floor(*v))
            throw Error(ErrorKind::Usage,
                        "expected --fourier-n-sweep as whole numbers 1..2048, got " + text::quoted(list));
        ns.push_back(static_cast<int>(*v));
    }
    std::sort(ns.begin(), ns.end());
    return ns;
}

void runCompare(const CompareOptions& o, const GlobalOptions& g) {
    if (int(!o.lights.empty()) + int(!o.lightsFile.empty()) + int(!o.plate.empty()) != 1)
        throw Error(ErrorKind::Usage,
                    "give the lights with --light X,Y[,R,G,B] (repeatable), --lights FILE or --plate IMAGE");
    std::string size = o.size;
    std::size_t plateLightCount = 0;
    std::vector<ghosts::Light> fromPlate;
    if (!o.plate.empty()) fromPlate = plateLights(o, size, plateLightCount);
    if (size.empty()) size = "1920x1080";
    ConsoleReporter reporter(g);
    scene::ComparisonSettings cs;
    std::tie(cs.width, cs.height) = parseFrameSize(size, "--size", 8, 8192);
    cs.ns = parseSweep(o.ns);
    const std::filesystem::path dir = scene::reportFolder(o.output);
    const optics::Lens lens = loadTraceableLens(o.lens, o.table.zoom, reporter);
    cs.sensorMm = lens.sensorMm.value_or(std::make_pair(36.0, 24.0));
    if (!o.sensorSize.empty()) cs.sensorMm = parseSensorSize(o.sensorSize, "--sensor-size");
    cs.lights = o.lightsFile.empty() ? fromPlate : scene::readLightsJson(o.lightsFile);
    for (const std::string& l : o.lights) cs.lights.push_back(scene::parseLight(l));
    if (!o.plate.empty())
        cs.lightsNote = "Lights: the " + std::to_string(cs.lights.size()) + " strongest of the " +
                        std::to_string(plateLightCount) + " found in `" + o.plate + "` (threshold " + o.threshold +
                        ").";
    cs.grid = o.grid;
    cs.table = o.table.settings();
    cs.sampling = samplingFrom(o.table.sampling);
    cs.diffraction = scene::diffractionNamed(o.diffraction, "the diffraction (--diffraction)");
    cs.commandLine = g.commandLine;
    cs.loadTable = [&](const optics::Lens& l, const ghosts::TableSettings& ts) {
        return loadTable(l, ts, g, reporter);
    };
    cs.loadShaped = [&](const optics::Lens& l, const ghosts::TableSettings& ss) {
        return loadShapedTable(l, ss, g, reporter);
    };
    cs.say = [&](const std::string& line) {
        if (!g.quiet) std::fprintf(stderr, "fourierflare: %s\n", line.c_str());
    };
    // The backend (EGL) last, after every option has been checked.
    cs.fourier = o.fourier.settings(g);
    cs.raster = gpu::polygonRaster(cs.fourier);
    if (o.fourier.errorOption && o.fourier.errorOption->count() > 0) cs.shapedError = o.fourier.error;
    cs.convolver = gpu::diffractionDevice(cs.fourier);
    scene::compareFlares(lens, cs, dir);
}

} // namespace

void addCompareCommand(CLI::App& app, GlobalOptions& global) {
    auto o = std::make_shared<CompareOptions>();
    CLI::App* cmd = app.add_subcommand(
        "compare", "Compare the traced flare of a scene with the fitted and the Fourier-aggregated ones");
    addLensArgument(*cmd, o->lens);
    cmd->add_option("--light", o->lights,
                    "A light at X,Y pixels, optionally with its RGB flux: X,Y[,R,G,B] (repeatable)");
    cmd->add_option("--lights", o->lightsFile, "Lights from a JSON file")->check(CLI::ExistingFile);
    cmd->add_option("--plate", o->plate, "Lights found in a plate as simulate finds them (the strongest --max-lights)");
    cmd->add_option("--threshold", o->threshold, "With --plate: the light threshold (as for simulate)");
    cmd->add_option("--max-lights", o->maxLights,
                    "With --plate: compare the strongest N lights (tracing costs seconds per light)")
        ->check(CLI::Range(1, 4096));
    cmd->add_option(
        "--size", o->size,
        "Frame size in pixels, WIDTHxHEIGHT (default: the plate's, else 1920x1080); the frame spans the sensor width");
    cmd->add_option("--fourier-n-sweep", o->ns, "Numbers of terms N for the error-against-N table, comma-separated");
    addDeprecated(*cmd, "--n", o->ns, "--fourier-n-sweep");
    cmd->add_option("-o,--output", o->output, "Report folder (created if missing)")->required();
    cmd->add_option("--grid", o->grid,
                    "Cells per side of each ghost's starting pupil grid for the traced reference (refined adaptively)")
        ->check(CLI::Range(4, 1024));
    o->table.addTo(*cmd);
    cmd->add_option("--sensor-size", o->sensorSize,
                    "Sensor size in mm, WIDTHxHEIGHT (default: the lens file's, else 36x24)");
    cmd->add_option(
           "--diffraction", o->diffraction,
           "Also show the lights' diffraction: physical (the iris's aberration-free PSF), traced (that and the "
           "PSF with the lens's traced wavefront at each light's field, compared) or off")
        ->check(CLI::IsMember({"off", "physical", "traced"}));
    o->fourier.addTo(*cmd);
    cmd->footer("Example: fourierflare compare lenses/double-gauss-50mm-f2.lens --light 1400,300 --light 600,700 "
                "--size 1920x1080 -o cmp/");
    cmd->callback([o, &global] {
        requireLens(o->lens);
        runCompare(*o, global);
    });
}

} // namespace ff::cli
