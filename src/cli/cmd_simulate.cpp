// `fourierflare simulate`: a lens against an HDR plate, end to end. Lights are found in the plate (or
// given), each gets the lens's ghosts from the ghost table, the flare is aggregated through the
// Fourier path and added to the plate; the EXR keeps every input channel and adds flare.* and
// composite.* (docs/simulate.md).

#include "cli/commands.h"
#include "cli/conventions.h"
#include "cli/fourier_choices.h"
#include "cli/option_parsing.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/text.h"
#include "core/units.h"
#include "diffraction/convolution.h"
#include "diffraction/psf.h"
#include "diffraction/wavefront.h"
#include "ff/version.h"
#include "fourier/render.h"
#include "ghosts/instancing.h"
#include "gpu/gl_backend.h"
#include "image/composite.h"
#include "image/light_detection.h"
#include "image/plate.h"
#include "optics/paraxial.h"
#include "scene/scene.h"
#include "trace/flare_raster.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
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
    FourierOptions fourier;
};

using Clock = std::chrono::steady_clock;
double since(Clock::time_point& t) {
    const auto now = Clock::now();
    const double s = std::chrono::duration<double>(now - t).count();
    t = now;
    return s;
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
};

class Simulation {
  public:
    Simulation(const SimulateOptions& o, const GlobalOptions& g) : o_(o), g_(g), reporter_(g) {
        if (o.gain < 0.0 || !std::isfinite(o.gain))
            throw Error(ErrorKind::Usage, "--flare-gain must be a finite number >= 0");
        if (o.diffractionGain < 0.0 || !std::isfinite(o.diffractionGain))
            throw Error(ErrorKind::Usage, "--diffraction-gain must be a finite number >= 0");
        // --sensor is the sensor plane, as in every command; a WxH size there is its old meaning
        // (now --sensor-size), accepted for one release.
        std::string sizeGiven = o.sensorSize;
        table_o_ = o.table;
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
            table_o_.sensor = o.sensor;
        }
        if (!sizeGiven.empty() && o.fov > 0.0)
            throw Error(ErrorKind::Usage, "give either --sensor-size WxH or --fov DEG, not both");
        detection_ = image::parseThreshold(o.threshold);
        detection_.blockSize = o.block;
        lens_ = loadTraceableLens(o.lens, o.table.zoom, reporter_);
        for (const std::string& l : o.lights) manualLights_.push_back(scene::parseLight(l));
        if (!o.lightsFile.empty()) {
            const auto more = scene::readLightsJson(o.lightsFile);
            manualLights_.insert(manualLights_.end(), more.begin(), more.end());
        }
        // Sensor width: --sensor-size, else from --fov through the EFL, else the lens file's, else 36 mm.
        sensorWidthMm_ = lens_.sensorMm ? lens_.sensorMm->first : 36.0;
        if (!sizeGiven.empty()) {
            sensorWidthMm_ = parseSensorSize(sizeGiven, sizeGiven == o.sensor ? "--sensor" : "--sensor-size").first;
        } else if (o.fov > 0.0) {
            sensorWidthMm_ =
                2.0 * std::abs(optics::paraxialEfl(lens_, lines::d)) * std::tan(0.5 * o.fov * std::numbers::pi / 180.0);
        }
        if (o.diffraction == "physical" || o.diffraction == "traced") {
            try {
                aperture_ = diffraction::apertureOf(lens_);
            } catch (const Error& e) {
                note(std::string("no diffraction: ") + e.what());
            }
        }
        detection_.lightImage = aperture_.has_value();
        // Options checked first: the backend (EGL) is touched last. The GL backend draws the shaped
        // model's polygons, or aggregates the fitted models with the Fourier options.
        fourier_ = o.fourier.settings(g);
        convolver_ = diffractionDevice(fourier_);
        if (o.ghostModel == "shaped") {
            raster_ = polygonRaster(fourier_);
            return;
        }
        // The Fourier-Bessel basis has no GL path (renderBessel runs on the CPU).
        if (fourier_.basis == fourier::Basis::Separable) gl_ = dynamic_cast<gpu::GlBackend*>(fourier_.backend.get());
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
        const image::Plate plate = image::readPlate(job.plate, limits);
        for (const auto& n : plate.notes) note(job.plate + ": " + n);
        const double tRead = since(t);

        // Lights: given, or found in the plate.
        std::vector<ghosts::Light> lights = manualLights_;
        image::DetectionReport found;
        if (lights.empty()) {
            found = image::detectLights(plate, detection_);
            for (const auto& l : found.lights) lights.push_back({l.x, l.y, l.flux});
            if (found.nonFinite)
                note(job.plate + ": " + std::to_string(found.nonFinite) +
                     " pixels are NaN or infinite: ignored by light detection (left as they are in the output)");
            if (found.emissiveZeroAlpha)
                note(job.plate + ": " + std::to_string(found.emissiveZeroAlpha) +
                     " bright pixels have alpha 0 (premultiplied emission): counted as light");
        }
        const double tDetect = since(t);

        // The flare, drawn into the plate's data window: ghosts::renderShaped from the shaped table,
        // or the table's fitted profiles aggregated through the Fourier path.
        std::vector<float> flareRgb, comp;
        std::string flareText;
        image::Metadata modelMeta;
        double tTable = 0.0;
        if (o_.ghostModel == "shaped") {
            const double pitch = sensorWidthMm_ / plate.displayWidth;
            // One table per display-window shape (the field it must cover).
            if (!shaped_ || shapedFor_ != std::make_pair(plate.displayWidth, plate.displayHeight)) {
                shapedFor_ = {plate.displayWidth, plate.displayHeight};
                ghosts::ShapedSettings ss;
                ss.sensorSizeMm = {sensorWidthMm_, pitch * plate.displayHeight};
                ss.sensor = sensorFrom(table_o_.sensor);
                ss.coating = coatingFrom(table_o_.coating);
                shaped_ = std::make_unique<ghosts::ShapedTable>(loadShapedTable(lens_, ss, g_, reporter_));
            }
            tTable = since(t);
            // The axis is at the display window's centre; the frame is the data window.
            trace::ImageFrame frame{plate.width, plate.height, pitch};
            frame.centreXMm = (plate.originX - plate.displayX + 0.5 * plate.width - 0.5 * plate.displayWidth) * pitch;
            frame.centreYMm =
                (0.5 * plate.displayHeight - (plate.originY - plate.displayY + 0.5 * plate.height)) * pitch;
            std::vector<ghosts::Light> shifted = lights;
            for (auto& l : shifted) {
                l.xPx -= plate.originX - plate.displayX;
                l.yPx -= plate.originY - plate.displayY;
                for (double& f : l.flux) f *= o_.gain;
            }
            ghosts::ShapedRender stats;
            std::size_t outside = 0;
            const fourier::FlareImage flare = scene::renderShapedScene(
                lens_, *shaped_, shifted, frame, sensorFrom(table_o_.sensor), &stats, &outside, raster_);
            if (outside)
                note(job.plate + ": " + std::to_string(outside) + " of " + std::to_string(lights.size()) +
                     " lights lie where no field angle of the lens images a source (outside its image circle on a " +
                     text::fixed(sensorWidthMm_, 1) + " mm wide sensor): they get no flare");
            flareRgb = flare.interleaved();
            flareText = std::to_string(stats.drawn) + " ghost instances drawn (" + std::to_string(stats.triangles) +
                        " triangles), " + std::to_string(stats.culled) + " culled holding at most " +
                        text::scientific(stats.culledShare, 2) + " of a light's ghost flux";
            modelMeta = {{"fourierflare:ghostModel", "shaped"},
                         {"fourierflare:backend", raster_ ? fourier_.backend->describe() : std::string("cpu")},
                         {"fourierflare:culled", std::to_string(stats.culled) + " ghost instances, at most " +
                                                     text::scientific(stats.culledShare, 3) +
                                                     " of a light's ghost flux"}};
        } else {
            if (!table_) {
                table_ = std::make_unique<ghosts::GhostTable>(loadTable(lens_, table_o_, g_, reporter_));
            }
            tTable = since(t);
            const ghosts::Camera cam{plate.displayWidth, plate.displayHeight, sensorWidthMm_};
            const auto profile = o_.ghostModel == "cos2" ? ghosts::Profile::Cos2 : ghosts::Profile::Gaussian;
            auto ghosts = scene::fourierGhosts(ghosts::instantiate(*table_, lights, cam, profile));
            // Display-window pixels to the data window's, and the artistic gain (1 = physical).
            for (auto& k : ghosts) {
                k.x -= plate.originX - plate.displayX;
                k.y -= plate.originY - plate.displayY;
                for (double& f : k.flux) f *= o_.gain;
            }
            const fourier::FourierRender flare = fourier::renderFourier(ghosts, plate.width, plate.height, fourier_);
            if (g_.verbose)
                note("fourier: " + flare.describe() + "; seconds: accumulate " +
                     text::fixed(flare.seconds.accumulate, 4) + ", evaluate " + text::fixed(flare.seconds.evaluate, 4) +
                     ", direct " + text::fixed(flare.seconds.direct, 4));
            flareRgb = flare.image.interleaved();
            // Composite on the device that holds the flare (bit-identical to image::composite) when the
            // flare is the ghosts alone.
            if (gl_ && !aperture_ && plate.width <= gl_->maxCompositeSide() && plate.height <= gl_->maxCompositeSide())
                comp = gl_->composite(plate.rgb());
            char buf[200];
            std::snprintf(buf, sizeof buf,
                          "%zu ghosts instanced; N %d x M %d, %zu through Fourier, %zu direct, %zu culled",
                          ghosts.size(), flare.plan.n, flare.plan.m, flare.fourierCount(), flare.directCount(),
                          flare.culledCount());
            flareText = buf;
            modelMeta = {{"fourierflare:ghostModel", o_.ghostModel},
                         {"fourierflare:fourier", flare.describe()},
                         {"fourierflare:backend", gl_ ? gl_->describe() : std::string("cpu")},
                         {"fourierflare:table", table_->settingsKey}};
        }
        const double tFlare = since(t);

        // Diffraction: the lights' image convolved with the lens's PSF, the lights' flux taken from
        // the pixels that hold it (docs/diffraction.md).
        std::vector<float> diffractionRgb(flareRgb.size(), 0.0f), ghostsRgb;
        image::Metadata diffractionMeta = {{"fourierflare:diffraction", "off"}};
        if (aperture_) {
            const double pitch = sensorWidthMm_ / plate.displayWidth;
            // The aberration-free PSF, made once per pixel pitch (a sequence pays it once); with
            // --diffraction traced only where a tile's own PSF cannot be made.
            auto ideal = [&]() -> const diffraction::Psf& {
                if (!psf_ || psfPitch_ != pitch) {
                    diffraction::PsfSettings ps;
                    ps.pitchMm = pitch;
                    psf_ = std::make_unique<diffraction::Psf>(diffraction::pixelPsf(*aperture_, ps));
                    psfPitch_ = pitch;
                }
                return *psf_;
            };
            psfText_.clear();
            std::vector<float> lightRgb = std::move(found.lightRgb);
            if (!manualLights_.empty())
                lightRgb = scene::splatLights(lights, plate.width, plate.height, plate.originX - plate.displayX,
                                              plate.originY - plate.displayY);
            double offFrame = 0.0;
            if (o_.diffraction == "traced") {
                // The lens's own wavefront at the lights' fields: one PSF per tile of the frame that
                // holds light, at its lights' centre (pixels of the data window; the axis at the
                // display window's centre).
                zones_.clear();
                auto psfAt = [&](double x, double y) {
                    const double xMm = (x + plate.originX - plate.displayX - 0.5 * plate.displayWidth) * pitch;
                    const double yMm = (0.5 * plate.displayHeight - (y + plate.originY - plate.displayY)) * pitch;
                    diffraction::PsfSettings ps;
                    ps.pitchMm = pitch;
                    try {
                        ps.pupil = diffraction::tracedPupil(lens_, xMm, yMm,
                                                            trace::sensorPlaneZ(lens_, sensorFrom(table_o_.sensor)));
                        diffraction::Psf p = diffraction::pixelPsf(*aperture_, ps);
                        if (psfText_.empty()) psfText_ = scene::describePsf(*aperture_, p);
                        zones_.push_back(text::fixed(x, 0) + "," + text::fixed(y, 0) + ": to " +
                                         std::to_string(p.radius) + " px");
                        return p;
                    } catch (const Error& e) {
                        note("the lights near pixel (" + text::fixed(x, 0) + ", " + text::fixed(y, 0) +
                             ") get the aberration-free PSF: " + e.what());
                        zones_.push_back(text::fixed(x, 0) + "," + text::fixed(y, 0) + ": aberration-free");
                        if (psfText_.empty()) psfText_ = scene::describePsf(*aperture_, ideal());
                        return ideal();
                    }
                };
                diffractionRgb = diffraction::zonedDiffractionLayer(lightRgb, plate.width, plate.height, kZones, kZones,
                                                                    psfAt, o_.diffractionGain, &offFrame, convolver_);
            } else {
                psfText_ = scene::describePsf(*aperture_, ideal());
                diffractionRgb = diffraction::diffractionLayer(lightRgb, plate.width, plate.height, ideal(),
                                                               o_.diffractionGain, &offFrame, convolver_);
            }
            diffractionMeta = {{"fourierflare:diffraction", describeDiffraction()}};
        }
        if (aperture_) {
            ghostsRgb = flareRgb;
            for (std::size_t i = 0; i < flareRgb.size(); ++i) flareRgb[i] += diffractionRgb[i];
        }
        if (comp.empty()) comp = image::composite(plate.rgb(), flareRgb);
        const double tDiffraction = since(t);

        image::Metadata meta = {
            {"Software", std::string("fourierflare ") + kVersion},
            {"fourierflare:commandLine", g_.commandLine},
            {"fourierflare:lens", lens_.file},
            {"fourierflare:lensHash", lens_.contentHash},
            {"fourierflare:plate", job.plate},
            {"fourierflare:lights", std::to_string(lights.size())},
            {"fourierflare:threshold",
             manualLights_.empty() ? text::roundTrip(found.threshold) : std::string("lights given")},
            {"fourierflare:sensorWidthMm", text::roundTrip(sensorWidthMm_)},
            {"fourierflare:flareGain", text::roundTrip(o_.gain)},
            {"fourierflare:channels",
             "input channels unchanged; ghosts.R/G/B = the ghosts; diffraction.R/G/B = the starburst (the lights' "
             "flux spread by the iris, taken from their pixels: sums to 0); flare.R/G/B = ghosts + diffraction; "
             "composite.R/G/B = plate + flare"}};
        meta.insert(meta.end(), modelMeta.begin(), modelMeta.end());
        meta.insert(meta.end(), diffractionMeta.begin(), diffractionMeta.end());
        const std::vector<float>& ghostsLayer = aperture_ ? ghostsRgb : flareRgb;
        image::writeSimulatedExr(
            job.output, plate,
            {{"ghosts", &ghostsLayer}, {"diffraction", &diffractionRgb}, {"flare", &flareRgb}, {"composite", &comp}},
            meta);
        if (!job.preview.empty()) {
            // The preview shows the flare where the plate is NaN or infinite.
            std::vector<float> shown = comp;
            for (std::size_t i = 0; i < shown.size(); ++i)
                if (!std::isfinite(shown[i])) shown[i] = flareRgb[i];
            image::writePng(job.preview, plate.width, plate.height, image::tonemapPreview(shown, o_.exposure), meta);
        }
        if (!job.previewFlare.empty())
            image::writePng(job.previewFlare, plate.width, plate.height,
                            image::tonemapPreview(flareRgb, image::autoExposure(flareRgb)), meta);
        if (!job.lightsOut.empty()) {
            nlohmann::json j;
            j["lights"] = nlohmann::json::array();
            for (std::size_t i = 0; i < lights.size(); ++i) {
                nlohmann::json l = {{"x", lights[i].xPx}, {"y", lights[i].yPx}, {"flux", lights[i].flux}};
                if (manualLights_.empty()) l["pixels"] = found.lights[i].pixels, l["peak"] = found.lights[i].peak;
                j["lights"].push_back(l);
            }
            writeFileAtomic(job.lightsOut, j.dump(2) + "\n");
        }
        const double tWrite = since(t);
        if (g_.quiet) return;
        std::string lightsText = manualLights_.empty() ? std::to_string(lights.size()) + " lights above luminance " +
                                                             text::fixed(found.threshold, 3) + " (plate max " +
                                                             text::fixed(found.maxLuminance, 1) + ")"
                                                       : std::to_string(lights.size()) + " lights given";
        if (lights.empty()) lightsText += ": no flare, the output is the plate plus a zero flare layer";
        std::fprintf(stderr,
                     "fourierflare: %s: %s, %s; read %.2f s, detect %.2f s, table %.2f s, flare %.2f s, diffraction "
                     "%.2f s, write %.2f s, total %.2f s -> %s\n",
                     job.plate.c_str(), lightsText.c_str(), flareText.c_str(), tRead, tDetect, tTable, tFlare,
                     tDiffraction, tWrite, std::chrono::duration<double>(Clock::now() - start).count(),
                     job.output.c_str());
    }

  private:
    void note(const std::string& s) const {
        if (!g_.quiet) std::fprintf(stderr, "fourierflare: note: %s\n", s.c_str());
    }

    std::string describeDiffraction() const {
        std::string zones;
        for (const std::string& z : zones_) zones += (zones.empty() ? "" : "; ") + z;
        return o_.diffraction + ", gain " + text::roundTrip(o_.diffractionGain) + "; " +
               (psfText_.empty() ? std::string("no light to diffract") : psfText_) +
               (o_.diffraction == "traced" ? "; the lens's wavefront per " + std::to_string(kZones) + " x " +
                                                 std::to_string(kZones) + " tile, at (px) " + zones
                                           : std::string()) +
               (convolver_ ? "; convolved on " + fourier_.backend->describe() : std::string("; convolved on the CPU"));
    }

    const SimulateOptions& o_;
    const GlobalOptions& g_;
    ConsoleReporter reporter_;
    image::DetectionSettings detection_;
    fourier::FourierSettings fourier_;
    optics::Lens lens_;
    std::vector<ghosts::Light> manualLights_;
    double sensorWidthMm_ = 36.0;
    std::unique_ptr<ghosts::GhostTable> table_;
    std::unique_ptr<ghosts::ShapedTable> shaped_;
    std::pair<int, int> shapedFor_;                 ///< the display window shaped_ was made for
    gpu::GlBackend* gl_ = nullptr;                  ///< fourier_.backend when it is the GL one (fitted models)
    ghosts::PolygonRaster* raster_ = nullptr;       ///< the GL backend's, drawing the shaped model
    diffraction::Convolver* convolver_ = nullptr;   ///< the GL backend's FFT, convolving the lights
    std::optional<diffraction::Aperture> aperture_; ///< with --diffraction physical
    TableOptions table_o_;                          ///< o_.table with the sensor plane --sensor gave
    std::unique_ptr<diffraction::Psf> psf_;         ///< aberration-free (the traced PSFs' fallback)
    std::string psfText_;                           ///< the PSF described (the first tile's with traced)
    std::vector<std::string> zones_;                ///< --diffraction traced: each tile's PSF, for the header
    static constexpr int kZones = 3;                ///< --diffraction traced: tiles per side of the frame
    double psfPitch_ = 0.0;                         ///< the pixel pitch psf_ was made for
    std::string checker_ = std::filesystem::read_symlink("/proc/self/exe").string(); // this program, for `plate-check`
};

void runSimulate(const SimulateOptions& o, const GlobalOptions& g) {
    const std::string ext = std::filesystem::path(o.output).extension().string();
    if (ext != ".exr" && ext != ".EXR")
        throw Error(ErrorKind::Usage,
                    "the output must be an .exr file (it holds the plate's channels and the flare layers), got " +
                        text::quoted(o.output));
    std::vector<FrameJob> jobs;
    if (o.frames.empty()) {
        jobs.push_back({o.plate, o.output, o.preview, o.previewFlare, o.lightsOut, 0});
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
                            o.lightsOut.empty() ? "" : frameName(o.lightsOut, f, "--lights-out"), f});
    }
    Simulation sim(o, g);
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
                    "EXR to write: the plate's channels unchanged + ghosts.R/G/B + diffraction.R/G/B + flare.R/G/B + "
                    "composite.R/G/B")
        ->required();
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
    cmd->add_option("--ghost-model", o->ghostModel,
                    "Ghost model: shaped (each ghost's traced mesh), gaussian or cos2 (the ghost table's fits, "
                    "aggregated through Fourier)")
        ->check(CLI::IsMember({"shaped", "gaussian", "cos2"}));
    o->table.addTo(*cmd, false, false);
    cmd->add_option("--max-pixels", o->maxPixels,
                    "Refuse plates with more pixels than this (checked before reading them)")
        ->check(CLI::Range(1.0, 1e10));
    cmd->add_option("--frames", o->frames,
                    "Render frames FIRST-LAST of a sequence: --plate, -o and the previews hold a %04d pattern");
    o->fourier.addTo(*cmd);
    cmd->footer("Examples:\n"
                "  fourierflare simulate --lens lenses/double-gauss-50mm-f2.lens --plate data/night-street.exr -o "
                "out/night-street.exr --preview out/night-street.png\n"
                "  fourierflare simulate --lens L.lens --plate shot.%04d.exr --frames 1001-1100 -o out/shot.%04d.exr");
    cmd->callback([o, &global] {
        requireLens(o->lens);
        runSimulate(*o, global);
    });
}

} // namespace ff::cli
