#pragma once
// Rasterising polygons of uniform density into a flux image with exact pixel-area coverage: what the
// traced renderer's adaptive grids (adaptive_grid.h) and the shaped ghosts draw with, and the frame
// that maps sensor millimetres to its pixels.

#include "trace/embree_tracer.h"
#include "trace/pupil_sampling.h"

#include <glm/vec2.hpp>

#include <span>
#include <vector>

namespace ff::trace {

/// Maps sensor millimetres (origin on the axis, +y up) to image pixels (origin top-left, +y down,
/// pixel centres at +0.5): one named conversion each way. A frame may be centred off the axis (the
/// local image of one ghost).
struct ImageFrame {
    int width = 0, height = 0;
    double pitchMm = 0.0;                    ///< sensor millimetres per pixel
    double centreXMm = 0.0, centreYMm = 0.0; ///< sensor point at the image centre (the axis by default)
    glm::dvec2 sensorToPixel(double xMm, double yMm) const {
        return {0.5 * width + (xMm - centreXMm) / pitchMm, 0.5 * height - (yMm - centreYMm) / pitchMm};
    }
    glm::dvec2 pixelToSensor(double px, double py) const {
        return {centreXMm + (px - 0.5 * width) * pitchMm, centreYMm + (0.5 * height - py) * pitchMm};
    }
};

struct RasterStats {
    double deposited = 0.0; ///< energy drawn into the image
    double offImage = 0.0;  ///< energy that landed outside it
    std::size_t quads = 0, splats = 0;
};

/// Accumulates polygons of uniform density with exact pixel-area coverage at a cost that grows with
/// their perimeter in pixels, not their area: each edge adds, row by row, its signed area to the few
/// columns it crosses, and one prefix sum per row (addTo, release) turns those into density x covered
/// area (the accumulation rasteriser of font renderers, with the density carried along). Any simple
/// polygon of either orientation is exact; results depend only on the order of the calls. Energies are
/// non-negative, so a negative prefix sum is rounding (~1e-16 of the row's partial sums) and reads 0.
class CoverageRaster {
  public:
    explicit CoverageRaster(const ImageFrame& frame);

    const ImageFrame& frame() const { return frame_; }

    /// Deposits energy e uniformly over the polygon `poly` (pixel coordinates, vertices in order); a
    /// polygon of zero area (a point, a segment) becomes a bilinear splat at its vertices' mean.
    /// Energy landing outside the frame is counted in stats.offImage, not drawn.
    void polygon(std::span<const glm::dvec2> poly, double e, RasterStats& stats);
    /// Energy e into pixel (px, py); outside the frame it is counted in stats.offImage.
    void pixel(int px, int py, double e, RasterStats& stats);
    /// Bilinear splat of energy e at pixel position p (pixel centres at +0.5).
    void point(const glm::dvec2& p, double e, RasterStats& stats);

    /// Adds the image drawn so far to `image` (frame-sized, row-major).
    void addTo(std::vector<double>& image) const;
    /// The image drawn (frame-sized, row-major), reusing the accumulator's memory.
    std::vector<double> release() &&;

  private:
    void edge(glm::dvec2 a, glm::dvec2 b, double d);
    void segment(const glm::dvec2& p0, const glm::dvec2& p1, double d);

    ImageFrame frame_;
    std::size_t stride_; ///< width + 2: the columns a row's last edge spills into
    std::vector<double> acc_;
};

} // namespace ff::trace
