// `fourierflare render`: the flare of one light source as an image (mode traced for now).

#include "cli/commands.h"
#include "cli/trace_choices.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/text.h"
#include "core/units.h"
#include "ff/version.h"
#include "image/image_output.h"
#include "trace/traced_flare.h"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <memory>

namespace ff::cli {

namespace {

struct RenderOptions {
    std::string lens;
    std::string angle;  ///< "DEG" or "DEG,AZ"
    std::string light;  ///< "X,Y" in pixels
    std::string size = "1280x720";
    std::string mode = "traced";
    std::string output, preview;
    int spectral = 0;
    std::string sampling = "reaim";
    int grid = 64;
    std::string sensor = "file";
    std::string coating = "file";
    std::string sensorSize;
    std::string zoom;
    double exposure = std::numeric_limits<double>::quiet_NaN();
};

std::pair<double, double> parsePair(const std::string& s, char sep, const char* what) {
    const auto parts = text::split(s, sep);
    if (parts.size() != 2 || !text::parseNumber(parts[0]) || !text::parseNumber(parts[1]))
        throw Error(ErrorKind::Usage, std::string("expected ") + what + ", got " + text::quoted(s));
    return {*text::parseNumber(parts[0]), *text::parseNumber(parts[1])};
}

void runRender(const RenderOptions& o, const GlobalOptions& g) {
    const auto start = std::chrono::steady_clock::now();
    for (const std::string& out : {o.output, o.preview})
        if (!out.empty() && samePath(out, o.lens)) throw Error(ErrorKind::Usage, "the output '" + out + "' is the input lens file");
    if (o.angle.empty() == o.light.empty()) throw Error(ErrorKind::Usage, "give exactly one of --angle DEG[,AZ] and --light X,Y");
    const auto [w, h] = parsePair(o.size, 'x', "--size WIDTHxHEIGHT in pixels (e.g. 1280x720)");
    if (w < 1 || h < 1 || w > 16384 || h > 16384 || w != std::floor(w) || h != std::floor(h))
        throw Error(ErrorKind::Usage, "--size must be whole pixels between 1 and 16384, got " + text::quoted(o.size));

    ConsoleReporter reporter(g);
    const optics::Lens lens = loadTraceableLens(o.lens, o.zoom, reporter);
    std::pair<double, double> sensorMm = lens.sensorMm.value_or(std::make_pair(36.0, 24.0));
    if (!o.sensorSize.empty()) sensorMm = parsePair(o.sensorSize, 'x', "--sensor-size WIDTHxHEIGHT in mm (e.g. 36x24)");

    trace::TracedFlareOptions t;
    t.frame = {static_cast<int>(w), static_cast<int>(h), sensorMm.first / w};
    t.spectralSamples = o.spectral;
    t.sampling = samplingFrom(o.sampling);
    t.grid = o.grid;
    t.sensor = sensorFrom(o.sensor);
    t.coating = coatingFrom(o.coating);
    if (!o.angle.empty()) {
        const auto parts = text::split(o.angle, ',');
        auto deg = parts.size() <= 2 ? text::parseNumber(parts[0]) : std::nullopt;
        auto az = parts.size() == 2 ? text::parseNumber(parts[1]) : std::optional<double>(0.0);
        if (!deg || !az || *deg < 0.0 || *deg >= 89.0) throw Error(ErrorKind::Usage, "expected --angle DEG[,AZ] with 0 <= DEG < 89, got " + text::quoted(o.angle));
        t.field = {degToRad(*deg), degToRad(*az)};
    } else {
        const auto [px, py] = parsePair(o.light, ',', "--light X,Y in pixels");
        const glm::dvec2 s = t.frame.pixelToSensor(px, py);
        t.field = trace::fieldForSensorPoint(lens, trace::sensorPlaneZ(lens, t.sensor), s.x, s.y);
    }

    const trace::TracedFlare flare = trace::renderTracedFlare(lens, t);
    std::string lambdas;
    for (double l : flare.wavelengthsNm) lambdas += (lambdas.empty() ? "" : " ") + text::fixed(l, 1);
    const image::Metadata meta = {{"Software", std::string("fourierflare ") + kVersion},
                                  {"fourierflare:commandLine", g.commandLine},
                                  {"fourierflare:lens", lens.file},
                                  {"fourierflare:lensHash", lens.contentHash},
                                  {"fourierflare:mode", o.mode},
                                  {"fourierflare:fieldAngleDeg", text::fixed(radToDeg(t.field.angleRad), 6)},
                                  {"fourierflare:azimuthDeg", text::fixed(radToDeg(t.field.azimuthRad), 6)},
                                  {"fourierflare:wavelengthsNm", lambdas},
                                  {"fourierflare:grid", std::to_string(o.grid) + " " + o.sampling},
                                  {"fourierflare:units", "flux per pixel relative to the direct image of the source (= 1 per channel)"}};
    image::writeExr(o.output, flare.width, flare.height, {"R", "G", "B"}, flare.rgb, meta);
    double drawn = 0.0, off = 0.0;
    std::size_t quads = 0, splats = 0;
    for (const auto& s : flare.stats) drawn += s.deposited, off += s.offImage, quads += s.quads, splats += s.splats;
    double ev = o.exposure;
    if (!o.preview.empty()) {
        if (std::isnan(ev)) ev = image::autoExposure(flare.rgb);
        image::writePng(o.preview, flare.width, flare.height, image::tonemapPreview(flare.rgb, ev), meta);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!g.quiet) {
        std::fprintf(stderr, "fourierflare: traced %zu ghosts at %zu wavelengths (field %.3f deg, azimuth %.1f deg): %zu cells as quads, %zu as splats\n",
                     flare.ghostCount, flare.wavelengthsNm.size(), radToDeg(t.field.angleRad), radToDeg(t.field.azimuthRad), quads, splats);
        std::fprintf(stderr, "fourierflare: ghost flux relative to the direct image, summed over wavelengths: %.4e in the frame, %.4e outside\n",
                     drawn, off);
        std::fprintf(stderr, "fourierflare: wrote %s%s%s in %.2f s\n", o.output.c_str(), o.preview.empty() ? "" : " and ",
                     o.preview.empty() ? "" : (o.preview + " (exposure " + text::fixed(ev, 2) + " EV)").c_str(), seconds);
    }
}

} // namespace

void addRenderCommand(CLI::App& app, GlobalOptions& global) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand("render", "Render the flare of one light source through a lens into an EXR image");
    cmd->add_option("lens", o->lens, "Lens file (.lens, .zmx or .dat)")->required()->check(CLI::ExistingFile);
    cmd->add_option("--angle", o->angle, "Field angle of the source in degrees, optionally with its azimuth: DEG[,AZ]");
    cmd->add_option("--light", o->light, "Image position of the source in pixels: X,Y (its field angle comes from the traced chief ray)");
    cmd->add_option("--size", o->size, "Image size in pixels, WIDTHxHEIGHT; the image spans the sensor width");
    cmd->add_option("--mode", o->mode, "Rendering mode: traced (every ghost ray-traced and rasterised)")->check(CLI::IsMember({"traced"}));
    cmd->add_option("-o,--output", o->output, "EXR file to write (R, G, B = the flare alone, linear)")->required();
    cmd->add_option("--preview", o->preview, "Also write a tonemapped PNG preview");
    cmd->add_option("--exposure", o->exposure, "Preview exposure in EV (default: automatic, the 99th percentile of the flare at 1.0)");
    cmd->add_option("--spectral", o->spectral, "Trace N wavelengths over 400-700 nm through the CIE 1931 matching functions (8-16); 0 = 450/550/650 nm")
        ->check(CLI::IsMember({0, 8, 9, 10, 11, 12, 13, 14, 15, 16}));
    cmd->add_option("--sampling", o->sampling, "Pupil sampling: reaim or paraxial-grid")->check(CLI::IsMember({"reaim", "paraxial-grid"}));
    cmd->add_option("--grid", o->grid, "Rays per side of each ghost's pupil grid")->check(CLI::Range(2, 1024));
    cmd->add_option("--sensor", o->sensor, "Sensor plane: file (the last thickness) or paraxial")->check(CLI::IsMember({"file", "paraxial"}));
    cmd->add_option("--coating", o->coating, "Coatings: file, none or mgf2")->check(CLI::IsMember({"file", "none", "mgf2"}));
    cmd->add_option("--sensor-size", o->sensorSize, "Sensor size in mm, WIDTHxHEIGHT (default: the lens file's, else 36x24)");
    cmd->add_option("--zoom", o->zoom, "Zoom position (label or 1-based index)");
    cmd->footer("Example: fourierflare render lenses/double-gauss-50mm-f2.lens --angle 10 --size 1280x720 --mode traced -o flare.exr --preview flare.png");
    cmd->callback([o, &global] { runRender(*o, global); });
}

} // namespace ff::cli
