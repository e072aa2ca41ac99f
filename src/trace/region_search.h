#pragma once
// The region search's steps (internal to ff_trace: pupil_sampling.cpp): the passes over one field
// and path at one wavelength and the pieces of light they find.

#include "trace/lit_points.h"
#include "trace/pupil_region.h"
#include "trace/sequential_tracer.h"

#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

namespace ff::trace::detail {

// The region search's shared steps, for one field and path: the coarse pass, the local passes that
// find a box's extent at their finer spacing, and the square over a box.
class RegionSearch {
  public:
    RegionSearch(const PupilFrame& frame, const Field& field, const LensAtWavelength& L,
                 const std::vector<PathStep>& steps, double maxRadius)
        : frame_(frame), field_(field), L_(L), steps_(steps), maxRadius_(maxRadius),
          half_(searchHalfSize(frame, field)), cell_(2.0 * half_ / kNominal),
          symmetric_(L.iris.mirrorSymmetricAbout(field.azimuthRad + 0.5 * std::numbers::pi)) {}

    // Coarse pass over everything that could enter the front surface, traced analytically. The
    // margins below are in cells of a 96 x 96 pass over it. The pass itself is denser where the
    // paraxial pupil is small against that square (a retrofocus wide angle's front opening dwarfs its
    // pupil): its spacing is an eighth of the pupil's radius (the scale of a ghost's own pupil; up to
    // 512 points across), or it steps over whole patches of light, or thin rings of it, at some field
    // angles and not others. Its points are jittered, each at a fixed place of its own in its cell:
    // light in a band thinner than the spacing and lying along the grid's rows or columns falls
    // between every point of a regular grid at some field angles, while each jittered point catches
    // it with a chance of its thickness over the spacing, so a band a few cells long is found at most
    // angles (a band along a row of a regular grid); findPieces completes what it found by
    // symmetry.
    LitGrid coarse() const {
        const int n = std::clamp(static_cast<int>(std::ceil(16.0 * half_ / frame_.radius)), kNominal, kMaxCoarse);
        return litGrid(gridBundle(frame_, field_, n, 0.0, 0.0, half_, false), L_, steps_, maxRadius_);
    }

    // The coarse points miss the tips of thin regions (two discs barely overlapping), and the box would
    // jump by a coarse cell, cutting off light, as the field angle moves them across the points. A local
    // pass over the box (two cells wider on every side, wider still while light reaches its outermost
    // points) finds the extent at its finer spacing.
    // The lit points of the last pass that found light go to *lit, if given.
    LitBox refine(const LitBox& found, std::vector<glm::dvec2>* lit = nullptr) const {
        double cx = 0.5 * (found.xMin + found.xMax), cy = 0.5 * (found.yMin + found.yMax);
        double h = 0.5 * std::max(found.xMax - found.xMin, found.yMax - found.yMin) + 2.0 * cell_;
        LitBox box = found;
        for (int pass = 0; pass < 4; ++pass) {
            const LitGrid grid = litGrid(gridBundle(frame_, field_, kLocal, cx, cy, h, false), L_, steps_, maxRadius_);
            const LitBox local = litBox(grid);
            if (local.empty()) break;
            box = local;
            if (lit) *lit = litPlaces(grid);
            if (!local.touchesEdge) break;
            cx = 0.5 * (local.xMin + local.xMax), cy = 0.5 * (local.yMin + local.yMax);
            h = 0.5 * std::max(local.xMax - local.xMin, local.yMax - local.yMin) + 4.0 * cell_;
        }
        // Never less than the coarse pass found: light thinner than the local spacing can fall
        // between its points.
        box.xMin = std::min(box.xMin, found.xMin), box.xMax = std::max(box.xMax, found.xMax);
        box.yMin = std::min(box.yMin, found.yMin), box.yMax = std::max(box.yMax, found.yMax);
        // Where the light is its own mirror image, so is light that crosses the mirror line: its box
        // holds its image. The passes meet a band thinner than their spacing at some of its points
        // and not others, and the box over those can stop short of one end.
        if (symmetric_) {
            const LitBox image = mirror(box);
            if (gap(box, image) < 0.0) box.extend(image);
        }
        return box;
    }

    // One cell of margin on every side, then a square over the box, holding the lit points given.
    PupilRegion square(const LitBox& box, std::vector<glm::dvec2> lit = {}) const {
        const double side = std::max(box.xMax - box.xMin, box.yMax - box.yMin) + 2.0 * cell_;
        return {0.5 * (box.xMin + box.xMax),
                0.5 * (box.yMin + box.yMax),
                0.5 * side,
                false,
                std::min(1.0, box.litArea / (side * side)),
                double(box.thinPoints) / box.litPoints,
                std::move(lit)};
    }

    // The square over what local passes find around a box the coarse pass found, with their lit points.
    PupilRegion region(const LitBox& found) const {
        std::vector<glm::dvec2> lit;
        const LitBox box = refine(found, &lit);
        return square(box, std::move(lit));
    }

    // Whether the field's light is mirror-symmetric across the line through the axis along the field's
    // azimuth: the surfaces and the barrel are surfaces of revolution, so it is unless the iris's
    // blades are not symmetric about that line.
    bool symmetric() const { return symmetric_; }

    // A point's mirror image across that line.
    glm::dvec2 mirror(glm::dvec2 p) const {
        const glm::dvec2 e(-std::sin(field_.azimuthRad), std::cos(field_.azimuthRad));
        return 2.0 * (p.x * e.x + p.y * e.y) * e - p;
    }

    // The box's mirror image across that line: the box over its corners' images (the same box where
    // the azimuth is a multiple of 90 deg), the same counts.
    LitBox mirror(const LitBox& b) const {
        LitBox m = b;
        m.xMin = m.yMin = 1e300, m.xMax = m.yMax = -1e300;
        for (const glm::dvec2 p : {glm::dvec2(b.xMin, b.yMin), glm::dvec2(b.xMax, b.yMin), glm::dvec2(b.xMin, b.yMax),
                                   glm::dvec2(b.xMax, b.yMax)}) {
            const glm::dvec2 q = mirror(p);
            m.xMin = std::min(m.xMin, q.x), m.xMax = std::max(m.xMax, q.x);
            m.yMin = std::min(m.yMin, q.y), m.yMax = std::max(m.yMax, q.y);
        }
        return m;
    }

    double cell() const { return cell_; }

  private:
    static constexpr int kNominal = 96, kMaxCoarse = 512, kLocal = 64;
    const PupilFrame& frame_;
    const Field& field_;
    const LensAtWavelength& L_;
    const std::vector<PathStep>& steps_;
    double maxRadius_, half_, cell_;
    bool symmetric_;
};

// Pieces a coarse pass tells apart (more: too broken up to).
constexpr std::size_t kMaxPieces = 64;

// What a coarse pass found: its pieces of light (none where there are more than kMaxPieces, too broken
// up to tell apart), the box over all of it, and the lit points of it and of the looks that added to it
// (with their mirror images, where the light is symmetric): the parts' grids must not let the light
// at any of them slip between their rays (PupilRegion::litPoints).
struct Found {
    std::vector<LitBox> pieces;
    LitBox all;
    std::vector<glm::dvec2> points;
};

// Adds a pass's lit points to what was found, with their images where the light is symmetric.
void addPoints(const RegionSearch& search, Found& f, const std::vector<glm::dvec2>& places);

// Whether b lies within `margin` of a (their boxes, each widened by margin, overlap).
inline bool near(const LitBox& a, const LitBox& b, double margin) {
    return gap(a, b) < margin;
}

// Completes what was found by symmetry: the light is its own mirror image (RegionSearch::mirror), so
// a piece whose image is far from every piece found was met on one side and stepped over on the
// other (jittered points fall differently on the two sides, which doubles the chances of meeting a
// thin band that crosses the mirror line, or one of a mirrored pair), and the image is added as a
// piece of its own.
void completeBySymmetry(const RegionSearch& search, Found& f);

// The coarse pass's pieces, completed by symmetry.
Found findPieces(const RegionSearch& search);

// The region with those of the points that lie in its square added to its lit points.
PupilRegion withPoints(PupilRegion r, const std::vector<glm::dvec2>& points);

} // namespace ff::trace::detail
