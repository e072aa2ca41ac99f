#pragma once
// The lights' diffraction through the iris: one driver for render, compare and simulate
// (docs/diffraction.md). The lights' image is convolved with the PSF: the aberration-free one
// (Physical; from the disk cache, kept for the next frame of the same pitch), or the lens's traced
// wavefront at the flux-weighted centre of each tile of a kDiffractionTiles^2 grid of the layer that
// holds light (Traced; the aberration-free PSF where a tile's cannot be made, with a note). Lights
// given beyond the layer reach into it through the aberration-free PSF: a sun just off the frame
// casts its spikes into it.

#include "core/reporter.h"
#include "diffraction/convolution.h"
#include "diffraction/psf.h"
#include "diffraction/pupil_mask.h"
#include "ghosts/instancing.h"
#include "optics/lens.h"
#include "scene/choices.h"
#include "trace/flare_raster.h"
#include "trace/sensor.h"

#include <memory>
#include <string>
#include <vector>

namespace ff::scene {

/// DiffractionRule::Traced: tiles per side of the layer, one traced PSF each.
constexpr int kDiffractionTiles = 3;

struct DiffractionSettings {
    DiffractionRule rule = DiffractionRule::Physical;     ///< Physical or Traced
    trace::SensorPlane sensor = trace::SensorPlane::File; ///< Traced: the plane the wavefront is taken at
    std::shared_ptr<const diffraction::PupilMask> dirt;   ///< on the front element, multiplying the iris (null: clean)
    diffraction::Convolver* convolver = nullptr;          ///< where the convolution runs (null: FFTW, its spectra kept)
    std::string convolverName = "the CPU";                ///< where that is, for the description
    bool useCache = true; ///< the aberration-free PSF read from the disk cache, or made and stored there
};

/// A layer's pixels within the frame the lights are given in: width x height pixels whose top-left
/// corner is (originX, originY) of `frame` (the display window, whose mapping gives the sensor
/// point of a pixel; a plate's data window is the layer).
struct LayerWindow {
    trace::ImageFrame frame;
    int width = 0, height = 0;
    int originX = 0, originY = 0;
};

/// What a layer holds of the lights' diffraction.
enum class DiffractionOutput {
    Spread, ///< the lights' image through the PSF (>= 0): render, compare
    Change  ///< gain x (that image - the lights' image), never taking more than a pixel's light: simulate
};

struct DiffractedLights {
    std::vector<float> layer; ///< R, G, B interleaved over the window
    double offFrame = 0.0;    ///< flux carried beyond the window (x gain), summed over the channels
    /// "<the PSF>[; the lens's traced wavefront per N x N tile holding light, at (px) X,Y: to R px; ...];
    /// convolved on <where>" ("no light to diffract" for the PSF where nothing was).
    std::string text;
};

class LightDiffraction {
  public:
    /// Throws ff::Error (Input) where the lens has no aperture stop (diffraction::apertureOf). The
    /// lens must outlive the driver.
    LightDiffraction(const optics::Lens& lens, DiffractionSettings settings, Reporter& reporter);
    ~LightDiffraction();

    /// The diffraction of `lightRgb` (the lights' pixels over the window: splatLights's or the
    /// detector's), and of the parts of the `given` lights' footprints (frame pixels) that fall
    /// beyond the window (none for lights found in a plate).
    DiffractedLights diffract(const std::vector<float>& lightRgb, const std::vector<ghosts::Light>& given,
                              const LayerWindow& window, DiffractionOutput output, double gain = 1.0);

    const diffraction::Aperture& aperture() const { return aperture_; }

  private:
    const diffraction::Psf& idealPsf(double pitchMm);

    const optics::Lens& lens_;
    DiffractionSettings s_;
    Reporter& reporter_;
    diffraction::Aperture aperture_;
    std::unique_ptr<diffraction::Psf> ideal_; ///< the aberration-free PSF, for idealPitch_
    double idealPitch_ = 0.0;
    diffraction::FftwConvolver cpu_; ///< the convolution where no convolver is given, kept from frame to frame
};

/// The lights through the lens's PSF over the frame (render --mode diffraction, compare): the spread
/// of LightDiffraction over the whole frame, with what left it (*offFrame, summed over the channels)
/// and the description (*summary, "<rule>; " and the driver's text).
std::vector<float> renderDiffraction(const optics::Lens& lens, const std::vector<ghosts::Light>& lights,
                                     const trace::ImageFrame& frame, const DiffractionSettings& settings,
                                     Reporter& reporter, double* offFrame = nullptr, std::string* summary = nullptr);

} // namespace ff::scene
