#pragma once
// A lens against an HDR plate (docs/simulate.md): the lights, given or found in the plate; the
// lens's ghosts (shaped, or the ghost table's fits aggregated through Fourier) drawn into the plate's
// data window; the iris's diffraction of the lights' flux; the layers and their composite. What the
// CLI's `simulate` and the Python module's simulate() run; reading and writing files is theirs.

#include "core/reporter.h"
#include "diffraction/convolution.h"
#include "diffraction/psf.h"
#include "fourier/plan.h"
#include "ghosts/instancing.h"
#include "ghosts/shaped_ghosts.h"
#include "image/light_detection.h"
#include "image/plate.h"
#include "optics/lens.h"
#include "scene/choices.h"
#include "scene/light_diffraction.h"
#include "scene/scene.h"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ff::scene {

struct SimulationSettings {
    GhostModel ghostModel = GhostModel::Shaped;
    DiffractionRule diffraction = DiffractionRule::Physical;
    double gain = 1.0;                                  ///< the flare's gain (1 = physical)
    double diffractionGain = 1.0;                       ///< the diffraction layer's gain (1 = physical)
    std::shared_ptr<const diffraction::PupilMask> dirt; ///< on the front element, multiplying the iris (null: clean)
    double sensorWidthMm = 0.0;         ///< the plate spans this width; 0: from fovDeg, else the lens file's, else 36
    double fovDeg = 0.0;                ///< > 0 (with sensorWidthMm 0): the width 2 EFL tan(fov / 2)
    image::DetectionSettings detection; ///< how lights are found (lightImage is set here)
    std::vector<ghosts::Light> lights;  ///< given (display-window pixels): no detection
    /// The ghost table's settings (gaussian, cos2); their sensor plane and coatings serve every model.
    ghosts::TableSettings table;
    fourier::FourierSettings fourier;        ///< the aggregator (gaussian, cos2)
    ghosts::PolygonRaster* raster = nullptr; ///< where the shaped polygons are drawn (null: the CPU)
    /// shaped: the flare's relative L2 error the instances through the grid's series may add (0: all
    /// drawn directly; docs/fourier.md, "Shaped ghosts through the series")
    double shapedError = kShapedError;
    diffraction::Convolver* convolver = nullptr; ///< the diffraction's convolution (null: FFTW)
    /// The ghost table / shaped table of the lens (default: ghosts::tableFor / shapedTableFor with
    /// the cache); a caller that reports builds supplies its own.
    std::function<ghosts::GhostTable(const optics::Lens&, const ghosts::TableSettings&)> loadTable;
    std::function<ghosts::ShapedTable(const optics::Lens&, const ghosts::TableSettings&)> loadShaped;
    /// The composite made on the device that holds a fitted flare without diffraction (bit-identical
    /// to image::composite), or empty where it cannot.
    std::function<std::vector<float>(const image::Plate&)> deviceComposite;
};

/// One plate's result; layers are R, G, B interleaved over the plate's data window.
struct SimulatedPlate {
    std::vector<ghosts::Light> lights; ///< display-window pixels
    image::DetectionReport found;      ///< where the lights were found (empty when given)
    /// ghosts: the ghosts; diffraction: the lights as the iris draws them (their pixels' flux spread
    /// into the starburst, the cores included, >= 0); lightPixels: the lights' pixels the diffraction
    /// spreads (>= 0; zero without diffraction); flare = ghosts + diffraction; composite = plate +
    /// flare - lightPixels (energy-conserving: the diffraction only moves the lights' flux).
    std::vector<float> ghosts, diffraction, lightPixels, flare, composite;
    std::string flareText;       ///< what was drawn (ghost instances, triangles or terms, culled)
    std::string diffractionText; ///< the PSFs and where the convolution ran ("off" without)
    std::string fourierText;     ///< gaussian, cos2: the aggregator's plan and its stage times
    std::size_t outside = 0;     ///< shaped: lights no field angle of the lens images (no flare)
    image::Metadata modelMeta;   ///< the ghost model's choices, for a file's header
    double detectSeconds = 0.0, tableSeconds = 0.0, flareSeconds = 0.0, diffractionSeconds = 0.0;
};

/// Checks the settings' numbers (the gains, the sensor's width or the field of view, not both):
/// ff::Error (Usage). Simulation's constructor calls it; a caller may call it first, to refuse bad
/// options before it opens a device.
void checkSettings(const SimulationSettings& settings);

/// Throws ff::Error (Input, naming the lens file) for a lens the simulation cannot take: an
/// anamorphic one, unless its ghosts are shaped (the two-dimensional table) and its diffraction is
/// the aberration-free PSF's or off.
void requireLensFor(const optics::Lens& lens, const SimulationSettings& settings);

class Simulation {
  public:
    /// Checks the settings (ff::Error, Usage) and finds the lens's aperture for the diffraction
    /// (where it has none, diffraction is off, with a note).
    Simulation(optics::Lens lens, SimulationSettings settings, Reporter& reporter);
    ~Simulation();
    Simulation(const Simulation&) = delete; ///< the diffraction driver refers to lens_
    Simulation& operator=(const Simulation&) = delete;

    /// The layers for one plate; tables and PSFs are kept for the next plate of the same shape.
    SimulatedPlate run(const image::Plate& plate);

    const optics::Lens& lens() const { return lens_; }
    double sensorWidthMm() const { return s_.sensorWidthMm; }

  private:
    void drawShaped(const image::Plate& plate, SimulatedPlate& out);
    void drawFitted(const image::Plate& plate, SimulatedPlate& out);
    void diffract(const image::Plate& plate, SimulatedPlate& out);

    optics::Lens lens_;
    SimulationSettings s_;
    Reporter& reporter_;
    std::unique_ptr<LightDiffraction> diffraction_; ///< null: diffraction off, or the lens has no aperture
    std::unique_ptr<ghosts::GhostTable> table_;
    std::unique_ptr<ghosts::ShapedTable> shaped_;
    std::pair<int, int> shapedFor_; ///< the display window shaped_ was made for
};

} // namespace ff::scene
