#pragma once
// Rasterising polygons of uniform density into a flux image with exact pixel-area coverage: what the
// traced renderer's adaptive grids (adaptive_grid.h) and the shaped ghosts draw with, and the frame
// that maps sensor millimetres to its pixels.

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

/// Accumulates polygons of uniform or linear density with exact pixel-area coverage at a cost that grows with
/// their perimeter in pixels, not their area: each edge adds, row by row, its signed area to the few
/// columns it crosses, and one prefix sum per row (addTo, release) turns those into density x covered
/// area (the accumulation rasteriser of font renderers, with the density carried along; a linear
/// density adds its slope along the row, summed twice, and the exact integrals in the columns an
/// edge crosses). Any simple
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
    /// Deposits energy e over the polygon with the density linear over it: (e / A) (1 + g . (p - c)),
    /// A its area, c its centroid, g the density's gradient relative to its mean (per pixel). Each
    /// pixel receives the exact integral of that density over its intersection with the polygon, so
    /// the total is e whatever g; g should keep the density non-negative over the polygon (a pixel
    /// whose sum is negative reads 0). A polygon inside one pixel puts e in that pixel; one of no
    /// area is splatted as above.
    void polygon(std::span<const glm::dvec2> poly, double e, const glm::dvec2& g, RasterStats& stats);
    /// Energy e into pixel (px, py); outside the frame it is counted in stats.offImage.
    void pixel(int px, int py, double e, RasterStats& stats);
    /// Bilinear splat of energy e at pixel position p (pixel centres at +0.5).
    void point(const glm::dvec2& p, double e, RasterStats& stats);

    /// Adds the image drawn so far to `image` (frame-sized, row-major).
    void addTo(std::vector<double>& image) const;
    /// The image drawn (frame-sized, row-major), reusing the accumulator's memory.
    std::vector<double> release() &&;

  private:
    /// A density d0 + dx x + dy y (pixel coordinates), signed as the edge adds it.
    struct Density {
        double d0 = 0.0, dx = 0.0, dy = 0.0;
    };
    void edge(glm::dvec2 a, glm::dvec2 b, const Density& d);
    void segment(const glm::dvec2& p0, const glm::dvec2& p1, double d);
    void linearSegment(const glm::dvec2& p0, const glm::dvec2& p1, const Density& d);

    ImageFrame frame_;
    std::size_t stride_; ///< width + 2: the columns a row's last edge spills into
    /// Per row, the entries whose prefix sum is each pixel's value (lanes_ 1); once a linear
    /// density is drawn, each entry has a slope beside it (lanes_ 2), whose prefix sum, summed
    /// again, is the ramp a slope adds from its column on.
    std::vector<double> acc_;
    std::size_t lanes_ = 1;
};

} // namespace ff::trace
