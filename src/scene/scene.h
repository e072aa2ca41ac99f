#pragma once
// A scene of lights through a lens, the stage that joins the tracer, the ghost models, the Fourier
// aggregator and the diffraction: the lights (by hand or from JSON), the aggregator's ghosts from
// table instances, the traced reference image of several lights, the shaped ghosts of a scene and its
// diffraction. What `render`, `compare`, `simulate` and the benches share.

#include "diffraction/convolution.h"
#include "diffraction/psf.h"
#include "fourier/ghost.h"
#include "ghosts/instancing.h"
#include "ghosts/shaped_ghosts.h"
#include "optics/lens.h"
#include "scene/choices.h"
#include "trace/traced_flare.h"

#include <string>
#include <string_view>
#include <vector>

namespace ff::scene {

/// "X,Y" or "X,Y,R,G,B" (pixels; RGB flux of the light's direct image, default 1,1,1).
ghosts::Light parseLight(const std::string& spec);

/// A lights file: {"lights": [{"x": X, "y": Y, "flux": [R, G, B]}, ...]} ("flux" optional).
std::vector<ghosts::Light> readLightsJson(const std::string& file);
/// The same from the file's bytes; `file` names it in errors (ff::Error, Input, with line:column).
std::vector<ghosts::Light> parseLightsJson(std::string_view text, const std::string& file);

/// An explicit ghost list (docs/fourier.md, "Ghost lists"):
/// {"ghosts": [{"x", "y", "profile": "gaussian"|"cos2", "widthX", "widthY", "flux" | "peak"}, ...]},
/// widths and flux/peak either one number or [R, G, B].
std::vector<fourier::Ghost> readGhostsJson(const std::string& file);
/// The same from the file's bytes; `file` names it in errors.
std::vector<fourier::Ghost> parseGhostsJson(std::string_view text, const std::string& file);

/// The aggregator's ghosts from table instances. The separable representation has axis-aligned
/// widths: an instance's radial and tangential widths are replaced by the ones with the same
/// second moments along x and y (w_x^2 = w_r^2 cos^2 phi + w_t^2 sin^2 phi); the x-y covariance of a
/// ghost that is neither radial-aligned nor round is dropped (a model error `compare` measures).
std::vector<fourier::Ghost> fourierGhosts(const std::vector<ghosts::GhostInstance>& instances);

struct TracedScene {
    fourier::FlareImage image;
    std::size_t ghostCount = 0, wavelengths = 0;
    double inFrame = 0.0, outside = 0.0; ///< ghost flux summed over wavelengths and lights (unit lights)
    std::size_t samples = 0, culled = 0, budgetHits = 0; ///< summed over the lights (trace::TracedFlare)
    double culledShare = 0.0;                            ///< largest share of a light's ghost flux culled
    int maxDepth = 0;
    /// "N rays, refined to depth D; culled K ghost(s) holding S of the ghost flux[; budget ...]".
    std::string describeRefinement() const;
};

/// The traced flare of all lights (each its own field, options.field ignored), summed with the
/// lights' RGB flux.
TracedScene renderTracedScene(const optics::Lens& lens, const std::vector<ghosts::Light>& lights,
                              trace::TracedFlareOptions options);

/// The traced flare of one source at options.field with unit flux.
TracedScene renderTracedField(const optics::Lens& lens, const trace::TracedFlareOptions& options);

/// The lights as an image (R, G, B interleaved, width x height): each light's flux splatted bilinearly
/// at its position (pixels, centres at +0.5) less (originX, originY).
std::vector<float> splatLights(const std::vector<ghosts::Light>& lights, int width, int height, double originX = 0.0,
                               double originY = 0.0);

/// Adds to `out` (R, G, B interleaved, width x height) gain x the PSF of each part of the lights'
/// footprints (splatLights's, less the origin) that falls outside the frame, reaching in: a sun just
/// off the frame casts its spikes into it (diffraction::addOutsideLight; what leaves the frame again
/// is added to *offFrame).
void addOffFrameLights(const std::vector<ghosts::Light>& lights, int width, int height, double originX, double originY,
                       const diffraction::Psf& psf, double gain, std::vector<float>& out, double* offFrame);

/// "working f/N, B blades; W wavelengths from the shortest to the longest (nm); the transform's near field (to R
/// px) joined from R/5 px to the far field (..., at E of the centre there) reaching the frame's edges[; dirt on the
/// front element (its key)]".
std::string describePsf(const diffraction::Aperture& aperture, const diffraction::Psf& psf,
                        const diffraction::PupilMask* dirt = nullptr);

/// The shaped hybrid's grid (ghosts::ShapedRenderSettings::grid): cells of this many pixels, and
/// this many cells of margin around the frame within the Fourier period.
constexpr int kShapedGridStep = 4;
constexpr int kShapedGridMargin = 8;
/// The shaped hybrid's default budget (simulate, compare): measured 0.0005-0.0015 relative L2
/// against every instance drawn directly on the plates of docs/performance.md ("Many lights").
constexpr double kShapedError = 1e-2;

/// The shaped ghosts of all lights (ghosts/shaped_ghosts.h), each light's field found as the traced
/// scene finds it, summed with the lights' RGB flux. With `outside`, a light that no field angle
/// images, or only one beyond the table's, draws nothing and is counted there; without it, the first
/// throws and the second is drawn at the table's last angle. `raster`: where the polygons are drawn
/// (null: the CPU). gridError > 0: the hybrid, the dim and soft instances through the Fourier
/// series of a grid of kShapedGridStep pixels within that estimated relative L2 error (docs/fourier.md).
fourier::FlareImage renderShapedScene(const optics::Lens& lens, const ghosts::ShapedTable& table,
                                      const std::vector<ghosts::Light>& lights, const trace::ImageFrame& frame,
                                      trace::SensorPlane sensor, ghosts::ShapedRender* stats = nullptr,
                                      std::size_t* outside = nullptr, ghosts::PolygonRaster* raster = nullptr,
                                      double gridError = 0.0);

/// The shaped ghosts of lights given by their fields, as renderShapedScene draws them.
fourier::FlareImage drawShaped(const ghosts::ShapedTable& table, const std::vector<ghosts::ShapedLight>& lights,
                               const trace::ImageFrame& frame, ghosts::ShapedRender* stats,
                               ghosts::PolygonRaster* raster, double gridError = 0.0);

} // namespace ff::scene
