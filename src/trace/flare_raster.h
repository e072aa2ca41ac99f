#pragma once
// Rasterising a traced ghost into a flux image: the pixel-exact coverage raster of polygons that the
// traced renderer's adaptive grids draw with (adaptive_grid.h), and the fixed-grid rasterisation
// below, which the ghost table's fits use.
//
// A path's bundle is traced twice over the same pupil grid: at the n x n cell centres and at the
// (n+1) x (n+1) cell corners. A cell carries the energy of its centre ray (weight x cell area, scaled
// by the caller), so the image's total flux is exactly the sum of the centre rays' energies; the
// four corner rays give the cell's footprint on the sensor:
//  - centre ray lost: the cell contributes nothing (a blocked ray never contributes);
//  - all four corners arrive and the quad is not folded: its energy is spread uniformly over the quad
//    with exact pixel-area coverage (as two triangles, split by area);
//  - a corner is lost (the cell straddles a vignetting edge) or the quad folds over itself (a
//    caustic): the footprint is the parallelogram that the local Jacobian, estimated from the
//    neighbouring centre rays, maps the cell to, drawn around the centre ray. Its corners come from
//    rays that did arrive, so no quad is stretched to a lost ray and no streak can appear;
//  - an isolated cell with no surviving neighbour along an axis: a bilinear splat at its centre ray.
// Energy landing outside the image is counted, not drawn.

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

/// The four corner positions of every cell of a bundle: a grid of (n+1) x (n+1) rays.
Bundle cornerBundle(const PupilFrame& frame, const Field& field, const Bundle& centres);

/// Adds one path's cells to `image` (width x height, row-major). energyScale multiplies every cell's
/// energy (e.g. 1 / direct-image energy to express flux relative to the source's direct image).
void rasterizeCells(const Bundle& centres, const std::vector<RayResult>& centreHits,
                    const std::vector<RayResult>& cornerHits, double energyScale, const ImageFrame& frame,
                    std::vector<double>& image, RasterStats& stats);

} // namespace ff::trace
