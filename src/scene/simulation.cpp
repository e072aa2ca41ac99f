#include "scene/simulation.h"

#include "core/error.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "core/units.h"
#include "fourier/backend.h"
#include "fourier/render.h"
#include "ghosts/shaped_cache.h"
#include "image/composite.h"
#include "optics/paraxial.h"
#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace ff::scene {

void requireLensFor(const optics::Lens& lens, const SimulationSettings& s) {
    if (lens.rotationallySymmetric()) return;
    if (s.ghostModel != GhostModel::Shaped)
        throw Error(ErrorKind::Input, SourceLocation{lens.file},
                    std::string("the lens has anamorphic surfaces: its ghosts are drawn by the shaped model, not ") +
                        toString(s.ghostModel) + " (the fits need a rotationally symmetric lens)");
    if (s.diffraction == DiffractionRule::Traced)
        throw Error(ErrorKind::Input, SourceLocation{lens.file},
                    "the lens has anamorphic surfaces: its diffraction is the aberration-free PSF's (physical), "
                    "not traced (the traced wavefront needs a rotationally symmetric lens)");
}

void checkSettings(const SimulationSettings& s) {
    if (s.gain < 0.0 || !std::isfinite(s.gain))
        throw Error(ErrorKind::Usage, "the flare gain must be a finite number >= 0");
    if (s.diffractionGain < 0.0 || !std::isfinite(s.diffractionGain))
        throw Error(ErrorKind::Usage, "the diffraction gain must be a finite number >= 0");
    if (!(s.sensorWidthMm >= 0.0) || !std::isfinite(s.sensorWidthMm))
        throw Error(ErrorKind::Usage, "the sensor width must be a finite number of mm > 0");
    if (!(s.fovDeg >= 0.0 && s.fovDeg < 180.0))
        throw Error(ErrorKind::Usage, "the field of view must be 0..180 degrees (0: not given)");
    if (s.sensorWidthMm > 0.0 && s.fovDeg > 0.0)
        throw Error(ErrorKind::Usage, "give either the sensor's size or the field of view, not both");
}

Simulation::Simulation(optics::Lens lens, SimulationSettings settings, Reporter& reporter)
    : lens_(std::move(lens)), s_(std::move(settings)), reporter_(reporter) {
    checkSettings(s_);
    if (s_.fovDeg > 0.0)
        s_.sensorWidthMm =
            2.0 * std::abs(optics::paraxialEfl(lens_, lines::d)) * std::tan(0.5 * s_.fovDeg * std::numbers::pi / 180.0);
    if (s_.sensorWidthMm == 0.0) s_.sensorWidthMm = lens_.sensorMm ? lens_.sensorMm->first : 36.0;
    if (!s_.loadTable)
        s_.loadTable = [this](const optics::Lens& l, const ghosts::TableSettings& t) {
            return ghosts::tableFor(l, t, true, {}, reporter_);
        };
    if (!s_.loadShaped)
        s_.loadShaped = [this](const optics::Lens& l, const ghosts::TableSettings& t) {
            return ghosts::shapedTableFor(l, t, true, reporter_);
        };
    if (s_.diffraction != DiffractionRule::Off) {
        DiffractionSettings d;
        d.rule = s_.diffraction;
        d.sensor = s_.table.sensor;
        d.dirt = s_.dirt;
        d.convolver = s_.convolver;
        if (s_.convolver && s_.fourier.backend) d.convolverName = s_.fourier.backend->describe();
        try {
            diffraction_ = std::make_unique<LightDiffraction>(lens_, std::move(d), reporter_);
        } catch (const Error& e) {
            reporter_.note({}, std::string("no diffraction: ") + e.what());
        }
    }
    s_.detection.lightImage = diffraction_ != nullptr;
}

Simulation::~Simulation() = default;

SimulatedPlate Simulation::run(const image::Plate& plate) {
    auto t = Clock::now();
    SimulatedPlate out;
    out.lights = s_.lights;
    if (out.lights.empty()) {
        out.found = image::detectLights(plate, s_.detection);
        for (const auto& l : out.found.lights) out.lights.push_back({l.x, l.y, l.flux});
        if (out.found.nonFinite)
            reporter_.note({plate.path},
                           std::to_string(out.found.nonFinite) +
                               " pixels are NaN or infinite: ignored by light detection (left as they are in the "
                               "output)");
        if (out.found.emissiveZeroAlpha)
            reporter_.note({plate.path}, std::to_string(out.found.emissiveZeroAlpha) +
                                             " bright pixels have alpha 0 (premultiplied emission): counted as light");
    }
    out.detectSeconds = lap(t);
    if (s_.ghostModel == GhostModel::Shaped)
        drawShaped(plate, out);
    else
        drawFitted(plate, out);
    t = Clock::now();
    out.diffraction.assign(out.flare.size(), 0.0f);
    out.lightPixels.assign(out.flare.size(), 0.0f);
    out.diffractionText = "off";
    out.ghosts = out.flare;
    if (diffraction_) {
        // diffract leaves d = gain (L * PSF - L) >= -L in out.diffraction; the composite is the plate
        // plus ghosts + d, the layers the lights as the iris draws them, L + d >= 0, and L.
        diffract(plate, out);
        for (std::size_t i = 0; i < out.flare.size(); ++i) out.flare[i] += out.diffraction[i];
        out.composite = image::composite(plate.rgb(), out.flare);
        for (std::size_t i = 0; i < out.flare.size(); ++i) {
            out.diffraction[i] += out.lightPixels[i];
            out.flare[i] = out.ghosts[i] + out.diffraction[i];
        }
    }
    if (out.composite.empty()) out.composite = image::composite(plate.rgb(), out.flare);
    out.diffractionSeconds = lap(t);
    return out;
}

void Simulation::drawShaped(const image::Plate& plate, SimulatedPlate& out) {
    auto t = Clock::now();
    const double pitch = s_.sensorWidthMm / plate.displayWidth;
    // One table per display-window shape (the field it must cover).
    if (!shaped_ || shapedFor_ != std::make_pair(plate.displayWidth, plate.displayHeight)) {
        shapedFor_ = {plate.displayWidth, plate.displayHeight};
        ghosts::TableSettings ss = s_.table;
        ss.sensorSizeMm = {s_.sensorWidthMm, pitch * plate.displayHeight};
        shaped_ = std::make_unique<ghosts::ShapedTable>(s_.loadShaped(lens_, ss));
    }
    out.tableSeconds = lap(t);
    // The axis is at the display window's centre; the frame is the data window.
    trace::ImageFrame frame{plate.width, plate.height, pitch};
    frame.centreXMm = (plate.dataOffsetX() + 0.5 * plate.width - 0.5 * plate.displayWidth) * pitch;
    frame.centreYMm = (0.5 * plate.displayHeight - (plate.dataOffsetY() + 0.5 * plate.height)) * pitch;
    std::vector<ghosts::Light> shifted = out.lights;
    for (auto& l : shifted) {
        l.xPx -= plate.dataOffsetX();
        l.yPx -= plate.dataOffsetY();
        for (double& f : l.flux) f *= s_.gain;
    }
    ghosts::ShapedRender stats;
    const fourier::FlareImage flare = renderShapedScene(lens_, *shaped_, shifted, frame, s_.table.sensor, &stats,
                                                        &out.outside, s_.raster, s_.shapedError);
    if (out.outside)
        reporter_.note({plate.path},
                       std::to_string(out.outside) + " of " + std::to_string(out.lights.size()) +
                           " lights lie where no field angle of the lens images a source (outside its image circle "
                           "on a " +
                           text::fixed(s_.sensorWidthMm, 1) + " mm wide sensor): they get no flare");
    out.flare = flare.interleaved();
    // Triangles per pixel (per grid cell) they cover, the mean over the instances: what the
    // subdivision costs against what it draws.
    out.flareText = std::to_string(stats.drawn) + " ghost instances drawn (" + std::to_string(stats.triangles) +
                    " triangles, " + text::fixed(stats.trianglesPerPixel, 2) + " per pixel covered (at most " +
                    text::fixed(stats.mostTrianglesPerPixel, 1) + "); " + std::to_string(stats.gridded) +
                    " of them through the Fourier series, " + std::to_string(stats.gridTriangles) +
                    " triangles on its grid, " + text::fixed(stats.gridTrianglesPerCell, 2) +
                    " per cell covered, estimated error " + text::scientific(stats.gridErrorEstimate, 2) + "), " +
                    std::to_string(stats.culled) + " culled holding at most " + text::scientific(stats.culledShare, 2) +
                    " of a light's ghost flux";
    out.modelMeta = {{"fourierflare:ghostModel", "shaped"},
                     {"fourierflare:backend", s_.raster ? s_.fourier.backend->describe() : std::string("cpu")},
                     {"fourierflare:culled", std::to_string(stats.culled) + " ghost instances, at most " +
                                                 text::scientific(stats.culledShare, 3) + " of a light's ghost flux"}};
    out.flareSeconds = lap(t);
}

void Simulation::drawFitted(const image::Plate& plate, SimulatedPlate& out) {
    auto t = Clock::now();
    if (!table_) table_ = std::make_unique<ghosts::GhostTable>(s_.loadTable(lens_, s_.table));
    out.tableSeconds = lap(t);
    const trace::ImageFrame display{plate.displayWidth, plate.displayHeight, s_.sensorWidthMm / plate.displayWidth};
    const auto profile = s_.ghostModel == GhostModel::Cos2 ? ghosts::Profile::Cos2 : ghosts::Profile::Gaussian;
    auto ghosts = fourierGhosts(ghosts::instantiate(*table_, out.lights, display, profile));
    // Display-window pixels to the data window's, and the gain (1 = physical).
    for (auto& k : ghosts) {
        k.x -= plate.dataOffsetX();
        k.y -= plate.dataOffsetY();
        for (double& f : k.flux) f *= s_.gain;
    }
    const fourier::FourierRender flare = fourier::renderFourier(ghosts, plate.width, plate.height, s_.fourier);
    out.flare = flare.image.interleaved();
    out.fourierText = flare.describe() + "; seconds: accumulate " + text::fixed(flare.seconds.accumulate, 4) +
                      ", evaluate " + text::fixed(flare.seconds.evaluate, 4) + ", direct " +
                      text::fixed(flare.seconds.direct, 4);
    // The composite on the device that holds the flare, when the flare is the ghosts alone.
    if (s_.deviceComposite && !diffraction_) out.composite = s_.deviceComposite(plate);
    char buf[200];
    std::snprintf(buf, sizeof buf, "%zu ghosts instanced; N %d x M %d, %zu through Fourier, %zu direct, %zu culled",
                  ghosts.size(), flare.plan.n, flare.plan.m, flare.fourierCount(), flare.directCount(),
                  flare.culledCount());
    out.flareText = buf;
    out.modelMeta = {{"fourierflare:ghostModel", toString(s_.ghostModel)},
                     {"fourierflare:fourier", flare.describe()},
                     {"fourierflare:backend", s_.fourier.backend ? s_.fourier.backend->describe() : std::string("cpu")},
                     {"fourierflare:table", table_->settingsKey}};
    out.flareSeconds = lap(t);
}

void Simulation::diffract(const image::Plate& plate, SimulatedPlate& out) {
    // The lights' pixels: the detector's, or the given lights splatted into the data window.
    out.lightPixels = s_.lights.empty() ? std::move(out.found.lightRgb)
                                        : splatLights(out.lights, plate.width, plate.height, plate.dataOffsetX(),
                                                      plate.dataOffsetY());
    const LayerWindow window{{plate.displayWidth, plate.displayHeight, s_.sensorWidthMm / plate.displayWidth},
                             plate.width,
                             plate.height,
                             plate.dataOffsetX(),
                             plate.dataOffsetY()};
    DiffractedLights d =
        diffraction_->diffract(out.lightPixels, s_.lights.empty() ? std::vector<ghosts::Light>{} : out.lights, window,
                               DiffractionOutput::Change, s_.diffractionGain);
    out.diffraction = std::move(d.layer);
    out.diffractionText =
        std::string(toString(s_.diffraction)) + ", gain " + text::roundTrip(s_.diffractionGain) + "; " + d.text;
}

} // namespace ff::scene
