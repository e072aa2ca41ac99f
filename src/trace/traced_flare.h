#pragma once
// The traced flare of one light source: every two-bounce ghost traced on an adaptively refined pupil
// grid (adaptive_grid.h) and rasterised at several wavelengths, combined into linear RGB. Pixel values are flux
// relative to the direct image of the same source: the direct image's flux is 1 in each channel, so a pixel holds the
// fraction of the source's light that lands there as ghosts. No gain is applied.
//
// Colour: `rgb` traces 650 / 550 / 450 nm into R / G / B. `spectral N` traces N wavelengths evenly over
// 400-700 nm and maps them to linear sRGB through the CIE 1931 2-degree matching functions (analytic
// fit of Wyman, Sloan & Shirley, JCGT 2(2), 2013), normalised so that a flat spectrum, like the
// source's direct image, is (1, 1, 1); out-of-gamut negatives are clipped to 0.

#include "optics/lens.h"
#include "trace/colour.h"
#include "trace/flare_raster.h"
#include "trace/ghost_analysis.h"
#include "trace/sensor.h"

#include <array>
#include <utility>
#include <vector>

namespace ff::trace {

struct TracedFlareOptions {
    Field field;
    ImageFrame frame;
    int spectralSamples = 0; ///< 0: the three RGB wavelengths; otherwise 8..16 wavelengths
    Sampling sampling = Sampling::Reaim;
    int grid = 32;        ///< cells per side of each path's starting pupil grid (before refinement)
    bool adaptive = true; ///< false: the starting grid drawn as it is, unrefined (a baseline)
    /// R >= 1: the starting grid x R and every refinement tolerance / R (RefineSettings::refined):
    /// 2 and 4 are the renders the default is checked against.
    double refinement = 1.0;
    /// Ghosts whose flux (summed over the wavelengths, on the starting grid) is under this share of
    /// the strongest ghost's are not refined or drawn; the share of the ghost flux dropped is reported.
    double cullFraction = 1e-3;
    SensorPlane sensor = SensorPlane::File;
    CoatingChoice coating = CoatingChoice::File;
};

struct TracedFlare {
    int width = 0, height = 0;
    std::vector<float> rgb; ///< width x height x 3, linear
    std::vector<double> wavelengthsNm;
    std::vector<RasterStats> stats; ///< per wavelength
    std::size_t ghostCount = 0;
    std::size_t culled = 0;     ///< ghosts culled (cullFraction)
    double culledShare = 0.0;   ///< their share of the ghost flux
    std::size_t samples = 0;    ///< rays traced for the drawn ghosts (starting grids and refinement)
    std::size_t budgetHits = 0; ///< ghost-wavelengths whose refinement stopped at the ray budget
    int maxDepth = 0;           ///< deepest refinement level reached
};

TracedFlare renderTracedFlare(const optics::Lens& lens, const TracedFlareOptions& options);

} // namespace ff::trace
