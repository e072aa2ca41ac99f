#pragma once
// A comparison of the flare models on one scene (docs/compare.md): the traced reference (and its own
// error against one refined twice as far), the shaped ghosts, and per profile the fitted ghosts drawn
// directly and aggregated through Fourier, with error metrics, difference pictures, the error
// against the number of terms, timings and, on request, the diffraction. What the CLI's `compare`
// and the Python module's compare() run.

#include "diffraction/convolution.h"
#include "fourier/plan.h"
#include "ghosts/instancing.h"
#include "ghosts/shaped_ghosts.h"
#include "optics/lens.h"
#include "scene/scene.h"

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace ff::scene {

struct ComparisonSettings {
    std::vector<ghosts::Light> lights; ///< pixels
    int width = 1920, height = 1080;   ///< the frame, pixels (8..8192)
    std::pair<double, double> sensorMm{36.0, 24.0};
    int grid = 32;                                     ///< the traced reference's starting pupil grid
    trace::Sampling sampling = trace::Sampling::Reaim; ///< the traced reference's pupil sampling
    /// The table's settings (the shaped ghosts and their fits); their sensor plane and coatings serve
    /// the traced reference too.
    ghosts::TableSettings table;
    fourier::FourierSettings fourier;                   ///< the aggregator (its error is the budget)
    std::vector<int> ns = {16, 32, 64, 128, 256};       ///< the error against N (each 1..2048)
    DiffractionRule diffraction = DiffractionRule::Off; ///< traced: the aberration-free PSF too
    ghosts::PolygonRaster* raster = nullptr;            ///< where the shaped polygons are drawn (null: the CPU)
    double shapedError = kShapedError;                  ///< the shaped hybrid's budget (0: no hybrid)
    diffraction::Convolver* convolver = nullptr;        ///< the diffraction's convolution (null: FFTW)
    /// The tables (default: from the cache, or built and cached).
    std::function<ghosts::GhostTable(const optics::Lens&, const ghosts::TableSettings&)> loadTable;
    std::function<ghosts::ShapedTable(const optics::Lens&, const ghosts::TableSettings&)> loadShaped;
    std::function<void(const std::string&)> say; ///< progress lines (may be empty)
    std::string commandLine;                     ///< recorded in the report and the images' headers
    std::string lightsNote;                      ///< where the lights came from, for report.md ("" none)
};

/// The report folder, created if missing; ff::Error (Usage) where it exists as something else,
/// (Runtime) where it cannot be made.
std::filesystem::path reportFolder(const std::string& path);

/// Runs the comparison and writes into `dir` (which must exist): traced, shaped, shaped-hybrid, fitted-* and
/// fourier-* as EXR and PNG, diff-*.png, error-vs-n.svg, report.md and report.json; returns the
/// report's JSON (the numbers: relative L2, PSNR, flux ratios, the error against N, seconds).
nlohmann::json compareFlares(const optics::Lens& lens, const ComparisonSettings& settings,
                             const std::filesystem::path& dir);

} // namespace ff::scene
