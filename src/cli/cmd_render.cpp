// `fourierflare render`: the flare of light sources as an image, traced, fitted or Fourier-aggregated.

#include "cli/commands.h"
#include "cli/conventions.h"
#include "cli/dirt_choices.h"
#include "cli/fourier_choices.h"
#include "cli/option_parsing.h"
#include "cli/trace_choices.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "core/units.h"
#include "diffraction/convolution.h"
#include "ff/version.h"
#include "fourier/render.h"
#include "gpu/backend_choice.h"
#include "image/image_output.h"
#include "image/plate.h"
#include "optics/lens_loader.h"
#include "optics/paraxial.h"
#include "scene/flare_render.h"
#include "scene/scene.h"
#include "trace/ghost_analysis.h"
#include "trace/traced_flare.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>

namespace ff::cli {

namespace {

struct RenderOptions {
    std::string lens;
    std::string angle;               ///< "DEG" or "DEG,AZ"
    std::vector<std::string> lights; ///< "X,Y[,R,G,B]" in pixels
    std::string lightsFile, ghostsFile;
    std::string size = "1280x720";
    std::string mode = "traced";
    std::string diffraction = "physical"; ///< --mode diffraction: physical or traced
    DirtOptions dirt;                     ///< --mode diffraction
    std::string ghostModel = "gaussian";
    std::string output, preview;
    std::vector<std::string> probes;
    int spectral = 0;
    int grid = 32;
    double refine = 1.0;
    /// The ghost table's options; its sampling, sensor plane and coatings serve the traced mode too.
    TableOptions table;
    std::string sensorSize;
    double exposure = std::numeric_limits<double>::quiet_NaN();
    bool desqueeze = false; ///< the preview stretched by the lens's squeeze
    FourierOptions fourier;
};

// --verbose: the aggregator's choices and where the time went.
void printPlan(const fourier::FourierRender& r) {
    const fourier::Plan& p = r.plan;
    std::fprintf(stderr, "fourierflare: fourier: %s\n", r.describe().c_str());
    if (p.basis == fourier::Basis::Separable) {
        std::size_t trimmed = 0;
        for (std::size_t k = 0; k < p.route.size(); ++k)
            trimmed += p.route[k] == fourier::Route::Fourier && (p.termsX[k] < p.n || p.termsY[k] < p.m);
        std::fprintf(
            stderr,
            "fourierflare: fourier: %s evaluation; %zu of %zu Fourier ghosts accumulated over fewer terms than N x M "
            "(their own need at a quarter of the budget); estimated work %.2f GFLOP\n",
            fourier::toString(p.evaluation), trimmed, p.fourier, p.estimatedGflop);
    }
    std::fprintf(stderr, "fourierflare: fourier: seconds: plan %.4f, accumulate %.4f, evaluate %.4f, direct %.4f\n",
                 r.seconds.plan, r.seconds.accumulate, r.seconds.evaluate, r.seconds.direct);
}

// The sources given are one of --angle, lights, --ghosts, and suit the mode; no output is an input.
void checkRenderSources(const RenderOptions& o) {
    const scene::RenderMode mode = scene::renderModeNamed(o.mode, "the mode (--mode)");
    for (const std::string& out : {o.output, o.preview})
        for (const std::string& in : {o.lens, o.lightsFile, o.ghostsFile})
            if (!out.empty() && !in.empty() && samePath(out, in))
                throw Error(ErrorKind::Usage, "the output '" + out + "' is an input file");
    const bool explicitGhosts = !o.ghostsFile.empty();
    const int sources = !o.angle.empty() + (!o.lights.empty() || !o.lightsFile.empty()) + explicitGhosts;
    if (sources != 1)
        throw Error(ErrorKind::Usage,
                    "give exactly one of --angle DEG[,AZ], --light X,Y (or --lights FILE) and --ghosts FILE");
    if (!o.lights.empty() && !o.lightsFile.empty())
        throw Error(ErrorKind::Usage, "give lights with --light or with --lights, not both");
    if (!o.angle.empty() && mode != scene::RenderMode::Traced && mode != scene::RenderMode::Shaped)
        throw Error(ErrorKind::Usage,
                    "--angle works with --mode traced or shaped; give the light's position with --light X,Y");
    if (explicitGhosts && mode == scene::RenderMode::Traced)
        throw Error(ErrorKind::Usage, "--ghosts needs --mode fitted or fourier (a ghost list has nothing to trace)");
    if (!explicitGhosts && o.lens.empty())
        throw Error(ErrorKind::Usage, "a lens file is required (unless --ghosts gives the ghosts)");
}

// One render: the image from scene::renderFlare (or renderGhosts for --ghosts), and what each mode
// adds to the header and the summary.
struct RenderJob {
    const RenderOptions& o;
    const GlobalOptions& g;
    image::Metadata& meta;
    std::string summary;
    double squeeze = 1.0; ///< the lens's anamorphic squeeze (optics::squeeze)

    // fitted / fourier: "drew N<kind> ghosts<of> directly", "aggregated N ghosts<of>: ...".
    void drawn(const scene::RenderedFlare& r, const scene::FlareSettings& s, const std::string& kind,
               const std::string& of) {
        if (!r.plan) {
            summary = "drew " + std::to_string(r.ghosts) + kind + " ghosts" + of + " directly";
            return;
        }
        meta.push_back({"fourierflare:fourier", r.plan->describe()});
        meta.push_back(
            {"fourierflare:backend", s.fourier.backend ? s.fourier.backend->describe() : std::string("cpu")});
        if (g.verbose) printPlan(*r.plan);
        summary = "aggregated " + std::to_string(r.ghosts) + " ghosts" + of + ": " + r.plan->describe();
    }

    void traced(const scene::RenderedFlare& r, std::size_t lights) {
        const scene::TracedScene& flare = r.traced;
        meta.push_back({"fourierflare:grid", std::to_string(o.grid) + " " + o.table.sampling});
        meta.push_back({"fourierflare:refine", text::fixed(o.refine, 3)});
        meta.push_back({"fourierflare:refinement", flare.describeRefinement()});
        summary = "traced " + std::to_string(flare.ghostCount) + " ghosts at " + std::to_string(flare.wavelengths) +
                  " wavelengths for " + std::to_string(std::max<std::size_t>(lights, 1)) +
                  " light(s); ghost flux relative to the direct image, summed "
                  "over wavelengths: " +
                  text::scientific(flare.inFrame, 4) + " in the frame, " + text::scientific(flare.outside, 4) +
                  " outside; " + flare.describeRefinement();
    }

    void diffraction(const scene::RenderedFlare& r, std::size_t lights) {
        meta.push_back({"fourierflare:diffraction", r.diffractionText});
        summary = "the lens's diffraction (" + r.diffractionText + ") of " + std::to_string(lights) + " light(s); " +
                  text::scientific(r.offFrame, 3) + " of the flux outside the frame";
    }

    void shaped(const scene::RenderedFlare& r) {
        summary = "shaped ghosts (" + std::to_string(r.shapedStored) + " of " + std::to_string(r.shapedGhosts) +
                  " ghosts, " + text::fixed(static_cast<double>(r.shapedBytes) / 1048576.0, 1) +
                  " MiB in memory); drew " + std::to_string(r.shaped.drawn) + " ghost instances (" +
                  std::to_string(r.shaped.triangles) + " triangles), culled " + std::to_string(r.shaped.culled) +
                  " holding " + text::scientific(r.shaped.culledShare, 2) + " of a light's ghost flux";
    }
};

// The --probe pixels, each inside the W x H frame.
std::vector<std::pair<double, double>> parseProbes(const RenderOptions& o, int W, int H) {
    std::vector<std::pair<double, double>> probes;
    for (const std::string& p : o.probes) {
        const auto xy = parsePair(p, ',', "--probe X,Y in pixels");
        if (xy.first < 0 || xy.second < 0 || xy.first >= W || xy.second >= H)
            throw Error(ErrorKind::Usage, "--probe " + p + " lies outside the " + o.size + " frame");
        probes.push_back(xy);
    }
    return probes;
}

// The settings a lens's flare takes from the options (sensor, traced renderer, table, field angle),
// with their metadata.
void lensSettings(const RenderOptions& o, const optics::Lens& lens, int W, int H, scene::FlareSettings& s,
                  image::Metadata& meta) {
    s.sensorMm = lens.sensorMm.value_or(std::make_pair(36.0, 24.0));
    if (!o.sensorSize.empty()) s.sensorMm = parseSensorSize(o.sensorSize, "--sensor-size");
    meta.push_back({"fourierflare:lens", lens.file});
    meta.push_back({"fourierflare:lensHash", lens.contentHash});
    meta.push_back(
        {"fourierflare:units", "flux per pixel relative to the direct image of a unit light (= 1 per channel)"});
    trace::TracedFlareOptions& t = s.traced;
    t.frame = {W, H, s.sensorMm.first / W};
    t.spectralSamples = o.spectral;
    t.sampling = samplingFrom(o.table.sampling);
    t.grid = o.grid;
    t.refinement = o.refine;
    t.sensor = sensorFrom(o.table.sensor);
    t.coating = coatingFrom(o.table.coating);
    s.table = o.table.settings();
    if (!o.angle.empty()) {
        const auto [deg, az] = parseAngle(o.angle, "--angle");
        s.field = trace::Field{degToRad(deg), degToRad(az)};
        meta.push_back({"fourierflare:fieldAngleDeg", text::fixed(deg, 6)});
        meta.push_back({"fourierflare:azimuthDeg", text::fixed(az, 6)});
    }
}

// The lens's flare of the options' lights, its summary and metadata in job.
fourier::FlareImage renderLensFlare(const RenderOptions& o, const GlobalOptions& g, int W, int H,
                                    scene::FlareSettings& s, RenderJob& job, Reporter& reporter) {
    // Any lens: scene::renderFlare refuses an anamorphic one in the modes that cannot take it.
    const optics::Lens lens = optics::loadLensAt(o.lens, o.table.zoom, &reporter);
    lensSettings(o, lens, W, H, s, job.meta);
    job.squeeze = optics::squeeze(lens, lines::d);
    if (job.squeeze != 1.0) job.meta.push_back({"fourierflare:squeeze", text::fixed(job.squeeze, 6)});
    std::vector<ghosts::Light> lights =
        o.lightsFile.empty() ? std::vector<ghosts::Light>{} : scene::readLightsJson(o.lightsFile);
    for (const std::string& l : o.lights) lights.push_back(scene::parseLight(l));
    if (s.mode == scene::RenderMode::Shaped) s.raster = gpu::polygonRaster(s.fourier);
    if (s.mode == scene::RenderMode::Diffraction) {
        s.convolver = gpu::diffractionDevice(s.fourier);
        s.dirt = o.dirt.mask(image::kThisProgram);
    }
    s.loadTable = [&](const optics::Lens& l, const ghosts::TableSettings& ts) { return loadTable(l, ts, g, reporter); };
    s.loadShaped = [&](const optics::Lens& l, const ghosts::TableSettings& ss) {
        return loadShapedTable(l, ss, g, reporter);
    };
    s.reporter = &reporter;
    scene::RenderedFlare r = scene::renderFlare(lens, lights, s);
    if (s.mode == scene::RenderMode::Traced)
        job.traced(r, lights.size());
    else if (s.mode == scene::RenderMode::Diffraction)
        job.diffraction(r, lights.size());
    else if (s.mode == scene::RenderMode::Shaped)
        job.shaped(r);
    else {
        job.meta.push_back({"fourierflare:ghostModel", o.ghostModel});
        job.drawn(r, s, " fitted", " of " + std::to_string(lights.size()) + " light(s)");
    }
    return std::move(r.image);
}

void runRender(const RenderOptions& o, const GlobalOptions& g) {
    const auto start = Clock::now();
    checkRenderSources(o);
    const auto [W, H] = parseFrameSize(o.size, "--size", 1, 16384);
    const std::vector<std::pair<double, double>> probes = parseProbes(o, W, H);

    ConsoleReporter reporter(g);
    image::Metadata meta = {{"Software", std::string("fourierflare ") + kVersion},
                            {"fourierflare:commandLine", g.commandLine},
                            {"fourierflare:mode", o.mode}};
    RenderJob job{o, g, meta, {}};
    scene::FlareSettings s;
    s.mode = scene::renderModeNamed(o.mode, "the mode (--mode)");
    s.profile = ghosts::profileNamed(o.ghostModel, "the ghost model (--ghost-model)");
    s.diffraction = scene::diffractionNamed(o.diffraction, "the diffraction (--diffraction)");
    s.fourier = o.fourier.settings(g);
    s.traced.frame = {W, H, 0.0};
    fourier::FlareImage image;
    if (!o.ghostsFile.empty()) {
        const auto ghosts = scene::readGhostsJson(o.ghostsFile);
        meta.push_back({"fourierflare:ghosts", o.ghostsFile});
        scene::RenderedFlare r = scene::renderGhosts(ghosts, s);
        job.drawn(r, s, "", "");
        meta.push_back({"fourierflare:units", "flux per pixel, in the ghost list's units"});
        image = std::move(r.image);
    } else {
        image = renderLensFlare(o, g, W, H, s, job, reporter);
    }
    const std::vector<float> rgb = image.interleaved();
    // Sensor pixels, the squeeze in the header (viewers desqueeze on display); the preview desqueezed
    // if asked.
    image::writeExr(o.output, W, H, {"R", "G", "B"}, rgb, meta, job.squeeze);
    double ev = o.exposure;
    if (!o.preview.empty()) {
        if (std::isnan(ev)) ev = image::autoExposure(rgb);
        if (o.desqueeze && job.squeeze != 1.0) {
            int w = 0;
            const std::vector<float> wide = image::stretchedRows(rgb, W, H, job.squeeze, &w);
            image::writePng(o.preview, w, H, image::tonemapPreview(wide, ev), meta);
        } else {
            if (o.desqueeze)
                reporter.note({}, "--desqueeze: the lens is not anamorphic (squeeze 1): the preview is as rendered");
            image::writePng(o.preview, W, H, image::tonemapPreview(rgb, ev), meta);
        }
    }
    for (const auto& [px, py] : probes) {
        const std::size_t p = static_cast<std::size_t>(py) * W + static_cast<std::size_t>(px);
        std::printf("probe %g,%g: %.9g %.9g %.9g\n", px, py, image.channel[0][p], image.channel[1][p],
                    image.channel[2][p]);
    }
    if (!g.quiet) {
        std::fprintf(stderr, "fourierflare: %s\n", job.summary.c_str());
        std::fprintf(stderr, "fourierflare: flux in the frame (R, G, B): %.4e %.4e %.4e\n", image.sum(0), image.sum(1),
                     image.sum(2));
        std::fprintf(stderr, "fourierflare: wrote %s%s%s in %.2f s\n", o.output.c_str(),
                     o.preview.empty() ? "" : " and ",
                     o.preview.empty() ? "" : (o.preview + " (exposure " + text::fixed(ev, 2) + " EV)").c_str(),
                     secondsSince(start));
    }
}

} // namespace

void addRenderCommand(CLI::App& app, GlobalOptions& global) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand("render", "Render the flare of light sources through a lens into an EXR image");
    addLensArgument(*cmd, o->lens, "Lens file (.lens, .zmx or .dat); not needed with --ghosts");
    cmd->add_option(
        "--angle", o->angle,
        "Field angle of one source in degrees, optionally with its azimuth: DEG[,AZ] (traced or shaped mode)");
    cmd->add_option("--light", o->lights,
                    "A light at X,Y pixels, optionally with its RGB flux: X,Y[,R,G,B] (repeatable)");
    cmd->add_option("--lights", o->lightsFile,
                    "Lights from a JSON file: {\"lights\": [{\"x\", \"y\", \"flux\": [R, G, B]}]}")
        ->check(CLI::ExistingFile);
    cmd->add_option("--ghosts", o->ghostsFile,
                    "Render an explicit ghost list (JSON, docs/fourier.md) instead of a lens's ghosts")
        ->check(CLI::ExistingFile);
    cmd->add_option("--size", o->size, "Image size in pixels, WIDTHxHEIGHT; the image spans the sensor width");
    cmd->add_option("--mode", o->mode,
                    "traced (every ghost ray-traced), shaped (the ghosts' traced meshes), fitted (the table's profiles "
                    "drawn directly), fourier (aggregated) or diffraction (the iris's starburst: the lights through "
                    "the lens's PSF)")
        ->check(CLI::IsMember({"traced", "shaped", "fitted", "fourier", "diffraction"}));
    cmd->add_option("--diffraction", o->diffraction,
                    "With --mode diffraction: physical (the iris's aberration-free PSF) or traced (each light through "
                    "the PSF with the lens's traced wavefront and vignetting at its field)")
        ->check(CLI::IsMember({"physical", "traced"}));
    o->dirt.addTo(*cmd);
    cmd->add_option("--ghost-model", o->ghostModel,
                    "The table's fitted profile drawn by fitted and fourier: gaussian or cos2 (the shaped model is "
                    "--mode shaped)")
        ->check(CLI::IsMember({"gaussian", "cos2"}));
    cmd->add_option("-o,--output", o->output, "EXR file to write (R, G, B = the flare alone, linear)")->required();
    cmd->add_option("--preview", o->preview, "Also write a tonemapped PNG preview");
    cmd->add_option("--probe", o->probes, "Print the image's R G B at pixel X,Y (repeatable)");
    cmd->add_flag("--desqueeze", o->desqueeze,
                  "Stretch the preview horizontally by the lens's anamorphic squeeze (EFL y / EFL x); the EXR stays "
                  "in sensor pixels with the squeeze as its pixel aspect ratio");
    cmd->add_option("--exposure", o->exposure,
                    "Preview exposure in EV (default: automatic, the 99th percentile of the flare at 1.0)");
    cmd->add_option(
           "--spectral", o->spectral,
           "Trace N wavelengths over 400-700 nm through the CIE 1931 matching functions (8-16); 0 = 450/550/650 nm")
        ->check(CLI::IsMember({0, 8, 9, 10, 11, 12, 13, 14, 15, 16}));
    cmd->add_option("--grid", o->grid,
                    "Cells per side of each ghost's starting pupil grid, refined adaptively (traced mode)")
        ->check(CLI::Range(2, 1024));
    cmd->add_option(
           "--refine", o->refine,
           "Refinement factor R of the traced mode: starting grid x R, every refinement tolerance / R (1, 2, 4...)")
        ->check(CLI::Range(1.0, 16.0));
    o->table.addTo(*cmd);
    cmd->add_option("--sensor-size", o->sensorSize,
                    "Sensor size in mm, WIDTHxHEIGHT (default: the lens file's, else 36x24)");
    o->fourier.addTo(*cmd);
    cmd->footer("Examples:\n"
                "  fourierflare render lenses/double-gauss-50mm-f2.lens --angle 10 --size 1280x720 -o flare.exr "
                "--preview flare.png\n"
                "  fourierflare render lenses/double-gauss-50mm-f2.lens --light 1400,300 --light 600,700,2,2,1 --size "
                "1920x1080 --mode fourier -o f.exr\n"
                "  fourierflare render --ghosts my-ghosts.json --size 1920x1080 --mode fourier --fourier-n 64 --probe "
                "960,540 -o g.exr");
    cmd->callback([o, &global] { runRender(*o, global); });
}

} // namespace ff::cli
