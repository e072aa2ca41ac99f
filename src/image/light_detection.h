#pragma once
// Finding the lights of a plate: pixels whose luminance is above a threshold, grouped into connected
// components (8-neighbourhood). Each light gets its flux-weighted centroid and its RGB flux (the sum of
// its pixels' values). A component larger than a block (the sun, a window) is split into blocks of
// blockSize pixels, each a light of its own, so an extended source makes an extended flare.
//
// Values: pixel values as stored (scene-linear). A pixel's RGB is its light whatever its alpha: with
// premultiplied alpha, A = 0 and RGB > 0 is pure emission (a flame over glass) and counts; such pixels
// are reported. NaN and infinite values are counted, reported and ignored (as 0). Negative values are
// ignored likewise.

#include "image/plate.h"

#include <array>
#include <string>
#include <vector>

namespace ff::image {

enum class ThresholdMode { Absolute, RelativeToMax, Percentile };

struct DetectionSettings {
    ThresholdMode mode = ThresholdMode::Absolute;
    double value = 2.0;           ///< absolute luminance; fraction of the maximum; or percentile (0-100)
    int blockSize = 32;           ///< pixels per side of the blocks an extended source is split into
    std::size_t maxLights = 4096; ///< beyond this, blocks double in size until the lights fit
    bool lightImage = false;      ///< also return the lights as an image (DetectionReport::lightRgb)
};

/// Parses "2" (absolute), "max:0.25" (fraction of the plate's largest luminance) or "p:99.9"
/// (luminance percentile); throws ff::Error (Usage).
DetectionSettings parseThreshold(const std::string& text);

struct DetectedLight {
    double x = 0.0, y = 0.0;      ///< flux-weighted centroid, pixels in the display window (pixel centres at +0.5)
    std::array<double, 3> flux{}; ///< sum of R, G, B over its pixels
    std::size_t pixels = 0;
    double peak = 0.0; ///< largest luminance
};

struct DetectionReport {
    std::vector<DetectedLight> lights;
    double threshold = 0.0; ///< the absolute luminance used
    double maxLuminance = 0.0;
    int blockSize = 0; ///< the block size finally used
    std::size_t nonFinite = 0, negative = 0, emissiveZeroAlpha = 0, brightPixels = 0;
    /// With DetectionSettings::lightImage, the lights as an image: R, G, B of the pixels above the
    /// threshold (negatives as 0), interleaved over the data window, 0 elsewhere. Their sum is the
    /// lights' flux.
    std::vector<float> lightRgb;
};

/// Rec. 709 luminance.
inline double luminance(double r, double g, double b) {
    return 0.2126 * r + 0.7152 * g + 0.0722 * b;
}

DetectionReport detectLights(const Plate& plate, const DetectionSettings& settings);

} // namespace ff::image
