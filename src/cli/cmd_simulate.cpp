// `fourierflare simulate`: a lens against an HDR plate, end to end. This file reads the plates
// (frame ranges too), writes the EXR (every input channel plus the chosen layers of ghosts.*,
// diffraction.*, flare.* and composite.*), the previews and the lights, and reports; scene::Simulation makes the layers
// (docs/simulate.md).

#include "cli/commands.h"
#include "cli/conventions.h"
#include "cli/dirt_choices.h"
#include "cli/fourier_choices.h"
#include "cli/option_parsing.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "ff/version.h"
#include "gpu/backend_choice.h"
#include "image/light_detection.h"
#include "image/plate.h"
#include "optics/lens_loader.h"
#include "scene/scene.h"
#include "scene/simulation.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <unistd.h>

namespace ff::cli {

namespace {

struct SimulateOptions {
    std::string lens, plate, output, preview, previewFlare, lightsOut, lightsFile;
    std::string sensor = "file"; ///< the sensor plane (or, deprecated, a WxH size)
    std::string sensorSize;
    double fov = 0.0;
    std::string threshold = "2";
    int block = 32;
    std::vector<std::string> lights;
    double exposure = 0.0;
    double gain = 1.0;
    std::string ghostModel = "shaped";
    std::string diffraction = "physical";
    double diffractionGain = 1.0;
    /// The ghost table's options (gaussian, cos2); its sensor plane and coatings serve the shaped model too.
    TableOptions table;
    double maxPixels = 8192.0 * 8192.0;
    std::string frames;
    std::string layers = "ghosts,diffraction,lights";
    DirtOptions dirt;
    bool half = false;
    bool skipExisting = false;
    FourierOptions fourier;
};

// The layers simulate can write, in the order they are written, with what each holds.
constexpr std::pair<const char*, const char*> kLayers[] = {
    {"ghosts", "the ghosts"},
    {"diffraction", "the lights as the iris draws them (their pixels' flux spread into the starburst, cores included)"},
    {"lights", "the lights' pixels the diffraction spreads"},
    {"flare", "ghosts + diffraction"},
    {"composite", "plate + flare - lights"}};

// --layers: names from kLayers, comma-separated, or "all"; returned in kLayers' order.
std::vector<std::string> parseLayers(const std::string& list) {
    std::vector<std::string> given;
    for (std::string_view part : text::split(list, ',')) given.emplace_back(part);
    if (list == "all") given.clear();
    std::vector<std::string> out;
    for (const std::string& g : given) {
        bool known = false;
        for (const auto& l : kLayers) known = known || g == l.first;
        if (!known)
            throw Error(ErrorKind::Usage, "--layers: " + text::quoted(g) +
                                              " is not a layer (ghosts, diffraction, lights, flare, composite or all)");
        if (std::count(given.begin(), given.end(), g) > 1)
            throw Error(ErrorKind::Usage, "--layers names " + text::quoted(g) + " twice");
    }
    for (const auto& l : kLayers)
        if (given.empty() || std::count(given.begin(), given.end(), l.first)) out.emplace_back(l.first);
    return out;
}

// "name.%04d.exr" with frame 7 -> "name.0007.exr"; the pattern must hold exactly one %d or %0Nd.
std::string frameName(const std::string& pattern, int frame, const char* what) {
    const auto p = pattern.find('%');
    if (p == std::string::npos || pattern.find('%', p + 1) != std::string::npos)
        throw Error(ErrorKind::Usage, std::string(what) +
                                          " needs one %d or %0Nd frame number pattern with --frames, got " +
                                          text::quoted(pattern));
    std::size_t q = p + 1;
    int width = 0;
    if (q < pattern.size() && pattern[q] == '0') {
        ++q;
        while (q < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[q])))
            width = width * 10 + (pattern[q++] - '0');
    }
    if (q >= pattern.size() || pattern[q] != 'd' || width > 12)
        throw Error(ErrorKind::Usage, std::string(what) + ": expected %d or %0Nd in " + text::quoted(pattern));
    char buf[32];
    std::snprintf(buf, sizeof buf, "%0*d", width, frame);
    return pattern.substr(0, p) + buf + pattern.substr(q + 1);
}

struct FrameJob {
    std::string plate, output, preview, previewFlare, lightsOut;
    int frame = 0;
    std::string commandLine; ///< the command that makes this frame's files, recorded in them

    /// Every file the job writes.
    std::vector<std::string> outputs() const {
        std::vector<std::string> out;
        for (const std::string* f : {&output, &preview, &previewFlare, &lightsOut})
            if (!f->empty()) out.push_back(*f);
        return out;
    }
};

// The command line that makes a job's files, recorded in them: without --skip-existing, and for
// frame `frame` of a sequence (frame >= 0) with --frames FIRST-LAST as --frames N-N. Neither changes
// the files' bytes, so a frame's files are the same whichever range or farm task rendered them.
std::string jobCommandLine(const std::vector<std::string>& arguments, int frame) {
    const std::string only = std::to_string(frame) + "-" + std::to_string(frame);
    std::string line;
    for (std::size_t i = 0; i < arguments.size(); ++i) {
        std::string a = arguments[i];
        if (a == "--skip-existing") continue;
        if (frame >= 0 && a.rfind("--frames=", 0) == 0) a = "--frames=" + only;
        line += (line.empty() ? "" : " ") + a;
        if (frame >= 0 && a == "--frames" && i + 1 < arguments.size()) {
            line += " " + only;
            ++i;
        }
    }
    return line;
}

// The command around scene::Simulation: the options into its settings, each frame's plate read and
// its EXR, previews and lights written, the reports.
class SimulateCommand {
  public:
    SimulateCommand(const SimulateOptions& o, const GlobalOptions& g) : o_(o), g_(g), reporter_(g) {
        layers_ = parseLayers(o.layers);
        optics::Lens lens;
        scene::SimulationSettings s = settings(o, g, lens);
        sim_ = std::make_unique<scene::Simulation>(std::move(lens), std::move(s), reporter_);
    }

    void run(const FrameJob& job) {
        auto t = Clock::now();
        const auto start = t;
        for (const std::string& out : {job.output, job.preview, job.previewFlare, job.lightsOut})
            for (const std::string& in : {job.plate, o_.lens, o_.lightsFile})
                if (!out.empty() && !in.empty() && samePath(out, in))
                    throw Error(ErrorKind::Usage, "the output '" + out + "' is an input file");
        image::PlateLimits limits;
        limits.maxPixels = static_cast<std::uint64_t>(o_.maxPixels);
        limits.checker = checker_;
        limits.cpuSeconds = image::plateCheckSeconds();
        const image::Plate plate = image::readPlate(job.plate, limits);
        image::checkLayersFit(plate, layers_);
        for (const auto& n : plate.notes) note(job.plate + ": " + n);
        const double tRead = lap(t);
        const scene::SimulatedPlate r = sim_->run(plate);
        t = Clock::now();
        const bool given = !manualLights_.empty();
        const std::vector<ghosts::Light>& lights = r.lights;

        image::Metadata meta = {
            {"Software", std::string("fourierflare ") + kVersion},
            {"fourierflare:commandLine", job.commandLine},
            {"fourierflare:lens", sim_->lens().file},
            {"fourierflare:lensHash", sim_->lens().contentHash},
            {"fourierflare:plate", job.plate},
            {"fourierflare:lights", std::to_string(lights.size())},
            {"fourierflare:threshold", given ? std::string("lights given") : text::roundTrip(r.found.threshold)},
            {"fourierflare:sensorWidthMm", text::roundTrip(sim_->sensorWidthMm())},
            {"fourierflare:flareGain", text::roundTrip(o_.gain)}};
        std::string channels = "input channels unchanged";
        std::vector<image::Layer> layers;
        for (const auto& [name, holds] : kLayers) {
            if (std::find(layers_.begin(), layers_.end(), name) == layers_.end()) continue;
            channels += std::string("; ") + name + ".R/G/B = " + holds + (o_.half ? " (half)" : "");
            const std::string n = name;
            layers.push_back({n, n == "ghosts"        ? &r.ghosts
                                 : n == "diffraction" ? &r.diffraction
                                 : n == "lights"      ? &r.lightPixels
                                 : n == "flare"       ? &r.flare
                                                      : &r.composite});
        }
        meta.push_back({"fourierflare:channels", channels});
        meta.insert(meta.end(), r.modelMeta.begin(), r.modelMeta.end());
        meta.push_back({"fourierflare:diffraction", r.diffractionText});
        if (const std::size_t saturated = image::writeSimulatedExr(job.output, plate, layers, meta, o_.half))
            note(job.output + ": " + std::to_string(saturated) +
                 " layer values lie beyond half's range and were written as +-65504 (write float: leave out --half)");
        if (!job.preview.empty()) {
            // The preview shows the flare where the plate is NaN or infinite.
            std::vector<float> shown = r.composite;
            for (std::size_t i = 0; i < shown.size(); ++i)
                if (!std::isfinite(shown[i])) shown[i] = r.flare[i];
            image::writePng(job.preview, plate.width, plate.height, image::tonemapPreview(shown, o_.exposure), meta);
        }
        if (!job.previewFlare.empty())
            image::writePng(job.previewFlare, plate.width, plate.height,
                            image::tonemapPreview(r.flare, image::autoExposure(r.flare)), meta);
        if (!job.lightsOut.empty()) {
            nlohmann::json j;
            j["lights"] = nlohmann::json::array();
            for (std::size_t i = 0; i < lights.size(); ++i) {
                nlohmann::json l = {{"x", lights[i].xPx}, {"y", lights[i].yPx}, {"flux", lights[i].flux}};
                if (!given) l["pixels"] = r.found.lights[i].pixels, l["peak"] = r.found.lights[i].peak;
                j["lights"].push_back(l);
            }
            writeFileAtomic(job.lightsOut, j.dump(2) + "\n");
        }
        const double tWrite = lap(t);
        if (g_.quiet) return;
        if (g_.verbose && !r.fourierText.empty()) note("fourier: " + r.fourierText);
        std::string lightsText = given ? std::to_string(lights.size()) + " lights given"
                                       : std::to_string(lights.size()) + " lights above luminance " +
                                             text::fixed(r.found.threshold, 3) + " (plate max " +
                                             text::fixed(r.found.maxLuminance, 1) + ")";
        if (lights.empty()) lightsText += ": no flare, the output is the plate plus a zero flare layer";
        std::fprintf(stderr,
                     "fourierflare: %s: %s, %s; read %.2f s, detect %.2f s, table %.2f s, flare %.2f s, diffraction "
                     "%.2f s, write %.2f s, total %.2f s -> %s\n",
                     job.plate.c_str(), lightsText.c_str(), r.flareText.c_str(), tRead, r.detectSeconds, r.tableSeconds,
                     r.flareSeconds, r.diffractionSeconds, tWrite, secondsSince(start), job.output.c_str());
    }

  private:
    void note(const std::string& s) const {
        if (!g_.quiet) std::fprintf(stderr, "fourierflare: note: %s\n", s.c_str());
    }

    // The settings from the options, checked in the order the options are documented; `lens` receives
    // the lens at its zoom position.
    scene::SimulationSettings settings(const SimulateOptions& o, const GlobalOptions& g, optics::Lens& lens) {
        scene::SimulationSettings s;
        s.ghostModel = scene::ghostModelNamed(o.ghostModel, "the ghost model (--ghost-model)");
        s.diffraction = scene::diffractionNamed(o.diffraction, "the diffraction (--diffraction)");
        s.gain = o.gain;
        s.diffractionGain = o.diffractionGain;
        if (s.diffraction != scene::DiffractionRule::Off) s.dirt = o.dirt.mask(checker_);
        // --sensor is the sensor plane, as in every command; a WxH size there is its old meaning
        // (now --sensor-size), accepted for one release.
        std::string sizeGiven = o.sensorSize;
        TableOptions table = o.table;
        if (o.sensor != "file" && o.sensor != "paraxial") {
            if (!o.sensorSize.empty())
                throw Error(ErrorKind::Usage,
                            "--sensor is the sensor plane: file or paraxial (the size is --sensor-size)");
            if (o.sensor.find('x') == std::string::npos)
                throw Error(ErrorKind::Usage, "expected --sensor file or paraxial (the sensor plane; its size is "
                                              "--sensor-size WxH), got " +
                                                  text::quoted(o.sensor));
            parseSensorSize(o.sensor, "--sensor");
            std::fprintf(stderr,
                         "fourierflare: warning: --sensor WxH is deprecated: use --sensor-size WxH (--sensor is "
                         "the sensor plane: file or paraxial; the old spelling goes in the next release)\n");
            sizeGiven = o.sensor;
        } else {
            table.sensor = o.sensor;
        }
        s.detection = image::parseThreshold(o.threshold);
        s.detection.blockSize = o.block;
        lens = optics::loadLensAt(o.lens, o.table.zoom, &reporter_);
        for (const std::string& l : o.lights) manualLights_.push_back(scene::parseLight(l));
        if (!o.lightsFile.empty()) {
            const auto more = scene::readLightsJson(o.lightsFile);
            manualLights_.insert(manualLights_.end(), more.begin(), more.end());
        }
        s.lights = manualLights_;
        if (!sizeGiven.empty()) {
            s.sensorWidthMm = parseSensorSize(sizeGiven, sizeGiven == o.sensor ? "--sensor" : "--sensor-size").first;
        }
        s.fovDeg = o.fov;
        scene::checkSettings(s);
        scene::requireLensFor(lens, s);
        s.table = table.settings();
        // Options checked first: the backend (EGL) is touched last. The GL backend draws the shaped
        // model's polygons, or aggregates the fitted models with the Fourier options.
        s.fourier = o.fourier.settings(g);
        s.convolver = gpu::diffractionDevice(s.fourier);
        if (s.ghostModel == scene::GhostModel::Shaped) {
            s.raster = gpu::polygonRaster(s.fourier);
            if (o.fourier.errorOption && o.fourier.errorOption->count() > 0) s.shapedError = o.fourier.error;
        } else if (s.fourier.basis == fourier::Basis::Separable) {
            // The Fourier-Bessel basis has no GL path (renderBessel runs on the CPU).
            if (gpu::GlBackend* gl = gpu::glBackendOf(s.fourier))
                s.deviceComposite = [gl](const image::Plate& plate) {
                    return gpu::compositeOnDevice(*gl, plate.width, plate.height, plate.rgb());
                };
        }
        s.loadTable = [this](const optics::Lens& l, const ghosts::TableSettings& ts) {
            return loadTable(l, ts, g_, reporter_);
        };
        s.loadShaped = [this](const optics::Lens& l, const ghosts::TableSettings& ss) {
            return loadShapedTable(l, ss, g_, reporter_);
        };
        return s;
    }

    const SimulateOptions& o_;
    const GlobalOptions& g_;
    ConsoleReporter reporter_;
    std::vector<ghosts::Light> manualLights_;
    std::vector<std::string> layers_;
    std::unique_ptr<scene::Simulation> sim_;
    std::string checker_ = image::kThisProgram; // this program, for `plate-check`
};

void runSimulate(const SimulateOptions& o, const GlobalOptions& g) {
    const std::string ext = std::filesystem::path(o.output).extension().string();
    if (ext != ".exr" && ext != ".EXR")
        throw Error(ErrorKind::Usage,
                    "the output must be an .exr file (it holds the plate's channels and the flare layers), got " +
                        text::quoted(o.output));
    std::vector<FrameJob> jobs;
    if (o.frames.empty()) {
        jobs.push_back({o.plate, o.output, o.preview, o.previewFlare, o.lightsOut, 0, jobCommandLine(g.arguments, -1)});
    } else {
        const auto parts = text::split(o.frames, '-');
        const auto a = parts.size() == 2 ? text::parseNumber(parts[0]) : std::nullopt,
                   b = parts.size() == 2 ? text::parseNumber(parts[1]) : std::nullopt;
        if (!a || !b || *a != std::floor(*a) || *b != std::floor(*b) || *a < 0 || *b < *a || *b - *a > 1e6)
            throw Error(ErrorKind::Usage,
                        "expected --frames FIRST-LAST (whole numbers, FIRST <= LAST), got " + text::quoted(o.frames));
        for (int f = static_cast<int>(*a); f <= static_cast<int>(*b); ++f)
            jobs.push_back({frameName(o.plate, f, "--plate"), frameName(o.output, f, "-o"),
                            o.preview.empty() ? "" : frameName(o.preview, f, "--preview"),
                            o.previewFlare.empty() ? "" : frameName(o.previewFlare, f, "--preview-flare"),
                            o.lightsOut.empty() ? "" : frameName(o.lightsOut, f, "--lights-out"), f,
                            jobCommandLine(g.arguments, f)});
    }
    SimulateCommand sim(o, g); // every option checked, even when no frame is left to render
    if (o.skipExisting) {
        // A job is done when all its files exist: each is written whole under its final name (a
        // temporary and a rename), so one that exists is complete.
        const std::size_t before = jobs.size();
        std::erase_if(jobs, [](const FrameJob& job) {
            const auto files = job.outputs();
            return std::all_of(files.begin(), files.end(), [](const std::string& f) {
                std::error_code ec;
                return std::filesystem::is_regular_file(f, ec);
            });
        });
        if (!g.quiet && jobs.size() < before)
            std::fprintf(stderr, "fourierflare: note: --skip-existing: %zu of %zu frames already written, skipped\n",
                         before - jobs.size(), before);
        if (jobs.empty()) return;
    }
    const bool bar = jobs.size() > 1 && !g.quiet && isatty(STDERR_FILENO);
    for (std::size_t i = 0; i < jobs.size(); ++i) {
        const FrameJob& job = jobs[i];
        if (bar) std::fprintf(stderr, "fourierflare: frame %d (%zu of %zu)\n", job.frame, i + 1, jobs.size());
        if (!std::filesystem::exists(job.plate))
            throw Error(ErrorKind::Input, SourceLocation{job.plate}, "no such plate");
        sim.run(job);
    }
}

} // namespace

void addPlateCheckCommand(CLI::App& app) {
    struct Options {
        std::string file;
        double maxPixels = 0.0;
        int maxChannels = 64;
    };
    auto o = std::make_shared<Options>();
    // Internal: simulate runs it as a separate process to read a plate that might crash or hang the
    // image library (image/plate.h). Not listed in the help.
    CLI::App* cmd =
        app.add_subcommand("plate-check", "Read a plate in full and report whether it is usable (internal)")->group("");
    cmd->add_option("--max-pixels", o->maxPixels)->required();
    cmd->add_option("--max-channels", o->maxChannels)->required();
    cmd->add_option("file", o->file)->required();
    cmd->callback([o] {
        image::PlateLimits limits;
        limits.maxPixels = static_cast<std::uint64_t>(o->maxPixels);
        limits.maxChannels = o->maxChannels;
        std::fflush(stdout);
        std::_Exit(image::checkPlate(o->file, limits));
    });
}

void addSimulateCommand(CLI::App& app, GlobalOptions& global) {
    auto o = std::make_shared<SimulateOptions>();
    CLI::App* cmd = app.add_subcommand(
        "simulate", "Add a lens's physically based flare to an HDR plate (EXR with flare layers + PNG preview)");
    addLensArgument(*cmd, o->lens);
    cmd->add_option("--plate", o->plate,
                    "Plate: any image OpenImageIO reads (EXR, HDR, TIFF, PNG, ...); with --frames a %04d pattern")
        ->required();
    cmd->add_option("-o,--output", o->output,
                    "EXR to write: the plate's channels unchanged + the --layers (name.R/G/B each)")
        ->required();
    cmd->add_option(
        "--layers", o->layers,
        "Layers added to the EXR, comma-separated: ghosts, diffraction (the lights as the iris draws them), "
        "lights (the lights' pixels it spreads), flare (= ghosts + diffraction), composite (= plate + flare "
        "- lights), or all");
    cmd->add_flag("--half", o->half, "Write the layers as half floats (the plate's channels keep their own format)");
    cmd->add_option("--preview", o->preview, "Also write the composite as a tonemapped PNG");
    cmd->add_option("--preview-flare", o->previewFlare, "Also write the flare alone as a PNG (automatic exposure)");
    cmd->add_option(
        "--sensor-size", o->sensorSize,
        "Sensor size in mm, WIDTHxHEIGHT; the plate spans its width (default: the lens file's, else 36x24)");
    cmd->add_option("--sensor", o->sensor,
                    "Sensor plane: file (the last thickness) or paraxial (the d line's focus); a WxH size here is the "
                    "deprecated spelling of --sensor-size");
    cmd->add_option("--fov", o->fov,
                    "Horizontal field of view in degrees instead of --sensor-size (sensor width = 2 EFL tan(fov/2))")
        ->check(CLI::Range(0.1, 170.0));
    cmd->add_option(
        "--threshold", o->threshold,
        "Light threshold on luminance: VALUE (absolute), max:FRACTION (of the plate's maximum) or p:PERCENTILE");
    cmd->add_option("--block", o->block, "Extended sources are split into blocks of this many pixels per side")
        ->check(CLI::Range(2, 4096));
    cmd->add_option("--light", o->lights,
                    "A light by hand at X,Y pixels with its RGB flux X,Y,R,G,B (repeatable; disables detection)");
    cmd->add_option("--lights", o->lightsFile, "Lights by hand from a JSON file (as written by --lights-out)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--lights-out", o->lightsOut, "Write the lights used (found or given) as JSON");
    cmd->add_option("--exposure", o->exposure, "Preview exposure in EV (the composite x 2^EV before the tonemap)");
    cmd->add_option("--flare-gain", o->gain,
                    "Multiply the flare (1 = physical: each ghost carries its traced share of its light's flux)");
    cmd->add_option("--diffraction", o->diffraction,
                    "The iris's starburst: physical (each light's flux spread by the iris's aberration-free PSF, "
                    "taken from the pixels that hold it), traced (the PSF with the lens's traced wavefront and "
                    "vignetting, per tile of a 3 x 3 grid holding light) or off")
        ->check(CLI::IsMember({"off", "physical", "traced"}));
    cmd->add_option("--diffraction-gain", o->diffractionGain,
                    "Multiply the diffraction layer (1 = physical); a pixel never loses more than its light");
    o->dirt.addTo(*cmd);
    cmd->add_option("--ghost-model", o->ghostModel,
                    "Ghost model: shaped (each ghost's traced mesh), gaussian or cos2 (the ghost table's fits, "
                    "aggregated through Fourier)")
        ->check(CLI::IsMember({"shaped", "gaussian", "cos2"}));
    o->table.addTo(*cmd, false, false, false);
    cmd->add_option("--max-pixels", o->maxPixels,
                    "Refuse plates with more pixels than this (checked before reading them)")
        ->check(CLI::Range(1.0, 1e10));
    cmd->add_option("--frames", o->frames,
                    "Render frames FIRST-LAST of a sequence: --plate, -o and the previews hold a %04d pattern");
    cmd->add_flag("--skip-existing", o->skipExisting,
                  "Skip the frames whose files (the EXR and each preview or lights file asked for) all exist: "
                  "rerun only the missing frames of a shot (docs/farm.md)");
    o->fourier.addTo(*cmd);
    cmd->footer("Examples:\n"
                "  fourierflare simulate --lens lenses/double-gauss-50mm-f2.lens --plate data/night-street.exr -o "
                "out/night-street.exr --preview out/night-street.png\n"
                "  fourierflare simulate --lens L.lens --plate shot.%04d.exr --frames 1001-1100 -o out/shot.%04d.exr\n"
                "Each plate is first read by a checker process, bounded by its CPU time (FF_PLATE_CHECK_SECONDS, "
                "default 3 s for the header) and 20 times that of wall-clock time (docs/simulate.md).");
    cmd->callback([o, &global] {
        requireLens(o->lens);
        runSimulate(*o, global);
    });
}

} // namespace ff::cli
