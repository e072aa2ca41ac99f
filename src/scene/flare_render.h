#pragma once
// The flare of lights through a lens in one of the render modes (docs/cli.md, `render`): traced,
// shaped, fitted, fourier or diffraction. What the CLI's `render` and the Python module's render()
// run; each adds its own header and summary from what the mode reports here.

#include "core/reporter.h"
#include "diffraction/convolution.h"
#include "fourier/render_result.h"
#include "ghosts/instancing.h"
#include "ghosts/shaped_ghosts.h"
#include "optics/lens.h"
#include "scene/choices.h"
#include "scene/light_diffraction.h"
#include "scene/scene.h"
#include "trace/traced_flare.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace ff::scene {

struct FlareSettings {
    RenderMode mode = RenderMode::Traced;
    ghosts::Profile profile = ghosts::Profile::Gaussian;     ///< fitted, fourier: the table's fits drawn
    DiffractionRule diffraction = DiffractionRule::Physical; ///< diffraction: physical or traced (never off)
    /// The frame (its pitch the sensor's width over its width), and for traced its grid, refinement
    /// and spectral samples; the sampling, sensor plane and coatings serve every mode.
    trace::TracedFlareOptions traced;
    std::optional<trace::Field> field;              ///< traced, shaped: one unit source at this field, not the lights
    std::pair<double, double> sensorMm{36.0, 24.0}; ///< the sensor the frame spans
    ghosts::TableSettings table;                    ///< shaped, fitted, fourier
    fourier::FourierSettings fourier;               ///< fourier
    ghosts::PolygonRaster* raster = nullptr;        ///< shaped: where the polygons are drawn (null: the CPU)
    diffraction::Convolver* convolver = nullptr;    ///< diffraction: the convolution (null: FFTW)
    std::shared_ptr<const diffraction::PupilMask> dirt; ///< diffraction: on the front element (null: clean)
    bool useCache = true;         ///< the default table loaders and the aberration-free PSF use the disk cache
    Reporter* reporter = nullptr; ///< notes (a tile's traced PSF that could not be made); null: none
    /// The tables (default: from the cache, or built and cached).
    std::function<ghosts::GhostTable(const optics::Lens&, const ghosts::TableSettings&)> loadTable;
    std::function<ghosts::ShapedTable(const optics::Lens&, const ghosts::TableSettings&)> loadShaped;
};

/// The image and what its mode reports.
struct RenderedFlare {
    fourier::FlareImage image;
    TracedScene traced;                             ///< traced (its image moved to `image`)
    std::optional<fourier::FourierRender> plan;     ///< fourier (its image moved to `image`)
    std::size_t ghosts = 0;                         ///< fitted, fourier: the ghosts drawn or aggregated
    ghosts::ShapedRender shaped;                    ///< shaped
    std::size_t shapedStored = 0, shapedGhosts = 0; ///< shaped: the table's ghosts kept, of all
    std::size_t shapedBytes = 0;                    ///< shaped: the table in memory
    std::string diffractionText;                    ///< diffraction: the PSFs
    double offFrame = 0.0;                          ///< diffraction: flux that left the frame
};

/// The diffraction driver's settings of a flare request.
DiffractionSettings diffractionSettings(const FlareSettings& settings);

/// Throws ff::Error (Input) for a lens the request cannot take: an anamorphic one, unless traced or
/// shaped, or through the aberration-free PSF (diffraction mode, physical rule).
void requireLensFor(const optics::Lens& lens, const FlareSettings& settings);

/// The lights' flare in settings.mode (fitted and fourier through the lens's ghost table).
RenderedFlare renderFlare(const optics::Lens& lens, const std::vector<ghosts::Light>& lights,
                          const FlareSettings& settings);

/// The lights' flare from a ghost table: its fits drawn directly (fitted) or aggregated (fourier).
RenderedFlare renderFromTable(const ghosts::GhostTable& table, const std::vector<ghosts::Light>& lights,
                              const FlareSettings& settings);

/// Ghosts drawn directly (fitted) or aggregated (fourier) over the settings' frame.
RenderedFlare renderGhosts(const std::vector<fourier::Ghost>& ghosts, const FlareSettings& settings);

} // namespace ff::scene
