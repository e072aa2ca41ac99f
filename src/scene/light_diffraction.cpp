#include "scene/light_diffraction.h"

#include "core/error.h"
#include "core/text.h"
#include "diffraction/psf_cache.h"
#include "diffraction/wavefront.h"
#include "scene/scene.h"

#include <algorithm>

namespace ff::scene {

LightDiffraction::LightDiffraction(const optics::Lens& lens, DiffractionSettings settings, Reporter& reporter)
    : lens_(lens), s_(std::move(settings)), reporter_(reporter), aperture_(diffraction::apertureOf(lens)) {}

LightDiffraction::~LightDiffraction() = default;

const diffraction::Psf& LightDiffraction::idealPsf(double pitchMm) {
    if (!ideal_ || idealPitch_ != pitchMm) {
        diffraction::PsfSettings ps;
        ps.pitchMm = pitchMm;
        ps.mask = s_.dirt;
        ideal_ = std::make_unique<diffraction::Psf>(diffraction::cachedPixelPsf(aperture_, ps, s_.useCache, reporter_));
        idealPitch_ = pitchMm;
    }
    return *ideal_;
}

DiffractedLights LightDiffraction::diffract(const std::vector<float>& lightRgb, const std::vector<ghosts::Light>& given,
                                            const LayerWindow& w, DiffractionOutput output, double gain) {
    DiffractedLights out;
    const double pitch = w.frame.pitchMm;
    diffraction::Convolver& convolver = s_.convolver ? *s_.convolver : cpu_;
    // One PSF's part of the layer: the tile's lights through it, as Spread or Change.
    auto part = [&](const std::vector<float>& lights, const diffraction::Psf& psf) {
        if (output == DiffractionOutput::Change)
            return diffraction::diffractionLayer(lights, w.width, w.height, psf, gain, &out.offFrame, &convolver);
        return convolver.convolve(lights, w.width, w.height, psf, &out.offFrame);
    };
    std::string psfText, tiles;
    auto describe = [&](const diffraction::Psf& psf) {
        if (psfText.empty()) psfText = describePsf(aperture_, psf, s_.dirt.get());
    };
    if (s_.rule == DiffractionRule::Traced) {
        const double sensorZ = trace::sensorPlaneZ(lens_, s_.sensor);
        out.layer = diffraction::sumOverTiles(
            lightRgb, w.width, w.height, kDiffractionTiles, kDiffractionTiles,
            [&](const std::vector<float>& tile, double x, double y) {
                const std::string at = text::fixed(x, 0) + "," + text::fixed(y, 0);
                tiles += (tiles.empty() ? "" : "; ") + at;
                try {
                    const glm::dvec2 mm = w.frame.pixelToSensor(x + w.originX, y + w.originY);
                    diffraction::PsfSettings ps;
                    ps.pitchMm = pitch;
                    ps.mask = s_.dirt;
                    ps.pupil = diffraction::tracedPupil(lens_, mm.x, mm.y, sensorZ);
                    const diffraction::Psf own = diffraction::pixelPsf(aperture_, ps);
                    describe(own);
                    tiles += ": to " + std::to_string(own.radius) + " px";
                    return part(tile, own);
                } catch (const Error& e) {
                    reporter_.note({}, "the lights near pixel (" + at + ") get the aberration-free PSF: " + e.what());
                    tiles += ": aberration-free";
                    describe(idealPsf(pitch));
                    return part(tile, idealPsf(pitch));
                }
            });
    } else {
        describe(idealPsf(pitch));
        out.layer = part(lightRgb, idealPsf(pitch));
    }
    const bool beyond = std::any_of(given.begin(), given.end(), [&](const ghosts::Light& l) {
        const double x = l.xPx - w.originX, y = l.yPx - w.originY;
        return !(x >= 1.0 && y >= 1.0 && x <= w.width - 1.0 && y <= w.height - 1.0);
    });
    if (beyond) {
        addOffFrameLights(given, w.width, w.height, w.originX, w.originY, idealPsf(pitch), gain, out.layer,
                          &out.offFrame);
        describe(idealPsf(pitch));
    }
    out.text = (psfText.empty() ? std::string("no light to diffract") : psfText) +
               (s_.rule == DiffractionRule::Traced
                    ? "; the lens's traced wavefront per " + std::to_string(kDiffractionTiles) + " x " +
                          std::to_string(kDiffractionTiles) + " tile holding light, at (px) " + tiles
                    : std::string()) +
               "; convolved on " + s_.convolverName;
    return out;
}

std::vector<float> renderDiffraction(const optics::Lens& lens, const std::vector<ghosts::Light>& lights,
                                     const trace::ImageFrame& frame, const DiffractionSettings& settings,
                                     Reporter& reporter, double* offFrame, std::string* summary) {
    LightDiffraction driver(lens, settings, reporter);
    DiffractedLights d = driver.diffract(splatLights(lights, frame.width, frame.height), lights,
                                         {frame, frame.width, frame.height}, DiffractionOutput::Spread);
    if (offFrame) *offFrame += d.offFrame;
    if (summary) *summary = std::string(toString(settings.rule)) + "; " + d.text;
    return std::move(d.layer);
}

} // namespace ff::scene
