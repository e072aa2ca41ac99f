#include "trace/pupil_sampling.h"

#include "core/units.h"
#include "optics/paraxial.h"

#include <algorithm>
#include <cmath>

namespace ff::trace {

std::size_t Bundle::launchedCount() const { return static_cast<std::size_t>(std::count(launched.begin(), launched.end(), 1)); }

glm::dvec3 fieldDirection(const Field& f, double eflSign) {
    // The image lies on the continuation of the chief ray through the nodal point: to image at
    // +r e (positive EFL), rays travel along +e transversally.
    const double s = std::sin(f.angleRad);
    const double ex = -std::sin(f.azimuthRad), ey = std::cos(f.azimuthRad);
    return {eflSign * s * ex, eflSign * s * ey, std::cos(f.angleRad)};
}

PupilFrame pupilFrame(const optics::Lens& lens) {
    const optics::FirstOrder fo = optics::analyzeFirstOrder(lens, lines::d);
    PupilFrame p;
    p.z = fo.entrancePupilZ;
    p.radius = 0.5 * fo.entrancePupilDiameter;
    p.eflSign = fo.efl >= 0.0 ? 1.0 : -1.0;
    const optics::Surface& first = lens.surfaces.front();
    p.frontRadius = first.semiAperture;
    const double rim = first.semiAperture > 0.0 ? first.sag(first.semiAperture).value_or(0.0) : 0.0;
    p.startZ = std::min(0.0, rim) - 1.0;
    return p;
}

Bundle gridBundle(const PupilFrame& frame, const Field& field, int n, double cx, double cy, double halfSize, bool discOnly) {
    Bundle b;
    b.n = n;
    b.cell = 2.0 * halfSize / n;
    b.cellArea = b.cell * b.cell;
    b.x0 = cx - halfSize;
    b.y0 = cy - halfSize;
    const glm::dvec3 d = fieldDirection(field, frame.eflSign);
    const double back = (frame.z - frame.startZ) / d.z; // from the pupil plane back to the start plane
    b.rays.resize(static_cast<std::size_t>(n) * n);
    b.launched.assign(b.rays.size(), 1);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = b.x0 + (i + 0.5) * b.cell, y = b.y0 + (j + 0.5) * b.cell;
            const std::size_t k = static_cast<std::size_t>(j) * n + i;
            b.rays[k] = {glm::dvec3(x, y, frame.z) - back * d, d};
            if (discOnly && x * x + y * y > frame.radius * frame.radius) b.launched[k] = 0;
        }
    return b;
}

namespace {

// Bounding box of the grid points of b whose rays arrive, or an empty box (xMin > xMax).
struct LitBox {
    double xMin = 1e300, xMax = -1e300, yMin = 1e300, yMax = -1e300;
    bool touchesEdge = false; ///< light at a grid point of the outermost ring
    double litArea = 0.0;     ///< lit points x cell area
    int litPoints = 0, thinPoints = 0; ///< lit points; those with no lit neighbour on either side along x or along y
    bool empty() const { return xMin > xMax; }
};

// A point is lit where its ray arrives within maxRadius of the axis (0: anywhere).
LitBox litBox(const Bundle& b, const LensAtWavelength& L, const std::vector<PathStep>& steps, double maxRadius) {
    std::vector<RayResult> hits(b.rays.size());
    traceAnalytic(L, steps, b.rays, hits, Weighting::None); // where light gets through, not how much
    const auto lit = [&](int i, int j) {
        if (i < 0 || j < 0 || i >= b.n || j >= b.n) return false;
        const RayResult& r = hits[static_cast<std::size_t>(j) * b.n + i];
        return r.status == optics::RayStatus::Ok && (maxRadius <= 0.0 || std::hypot(r.sensorPoint.x, r.sensorPoint.y) <= maxRadius);
    };
    LitBox box;
    for (int j = 0; j < b.n; ++j)
        for (int i = 0; i < b.n; ++i) {
            if (!lit(i, j)) continue;
            const double x = b.x0 + (i + 0.5) * b.cell, y = b.y0 + (j + 0.5) * b.cell;
            box.xMin = std::min(box.xMin, x), box.xMax = std::max(box.xMax, x);
            box.yMin = std::min(box.yMin, y), box.yMax = std::max(box.yMax, y);
            box.touchesEdge = box.touchesEdge || i == 0 || j == 0 || i == b.n - 1 || j == b.n - 1;
            ++box.litPoints;
            box.thinPoints += (!lit(i - 1, j) && !lit(i + 1, j)) || (!lit(i, j - 1) && !lit(i, j + 1));
        }
    box.litArea = box.litPoints * b.cell * b.cell;
    return box;
}

} // namespace

double searchHalfSize(const PupilFrame& frame, const Field& field) {
    const double shift = std::abs(std::tan(field.angleRad)) * std::abs(frame.z - frame.startZ);
    return std::max(frame.frontRadius, frame.radius) + shift + frame.radius;
}

PupilRegion pupilRegion(const PupilFrame& frame, const Field& field, Sampling sampling, const LensAtWavelength& L,
                        const std::vector<PathStep>& steps, double maxRadiusMm) {
    if (sampling == Sampling::ParaxialGrid) return {0.0, 0.0, frame.radius, true};

    // Coarse pass over everything that could enter the front surface, traced analytically.
    const double half = searchHalfSize(frame, field);
    // The margins below are in cells of a 96 x 96 pass over it. The pass itself is denser where the
    // paraxial pupil is small against that square (a retrofocus wide angle's front opening dwarfs its
    // pupil): its spacing is at most an eighth of the pupil's radius, the scale of a ghost's own pupil,
    // or it steps over whole patches of light, or thin rings of it, at some field angles and not others.
    constexpr int kNominal = 96, kMaxCoarse = 512, kLocal = 64;
    const double cell = 2.0 * half / kNominal;
    const int nCoarse = std::clamp(static_cast<int>(std::ceil(16.0 * half / frame.radius)), kNominal, kMaxCoarse);
    const LitBox found = litBox(gridBundle(frame, field, nCoarse, 0.0, 0.0, half, false), L, steps, maxRadiusMm);
    if (found.empty()) return {0.0, 0.0, frame.radius, true}; // nothing gets through: the paraxial pupil
    // The coarse points miss the tips of thin regions (two discs barely overlapping), and the box would
    // jump by a coarse cell, cutting off light, as the field angle moves them across the points. A local
    // pass over the box (two cells wider on every side, wider still while light reaches its outermost
    // points) finds the extent at its finer spacing.
    double cx = 0.5 * (found.xMin + found.xMax), cy = 0.5 * (found.yMin + found.yMax);
    double h = 0.5 * std::max(found.xMax - found.xMin, found.yMax - found.yMin) + 2.0 * cell;
    LitBox box = found;
    for (int pass = 0; pass < 4; ++pass) {
        const LitBox local = litBox(gridBundle(frame, field, kLocal, cx, cy, h, false), L, steps, maxRadiusMm);
        if (local.empty()) break;
        box = local;
        if (!local.touchesEdge) break;
        cx = 0.5 * (local.xMin + local.xMax), cy = 0.5 * (local.yMin + local.yMax);
        h = 0.5 * std::max(local.xMax - local.xMin, local.yMax - local.yMin) + 4.0 * cell;
    }
    // One cell of margin on every side, then a square over the box.
    const double side = std::max(box.xMax - box.xMin, box.yMax - box.yMin) + 2.0 * cell;
    return {0.5 * (box.xMin + box.xMax), 0.5 * (box.yMin + box.yMax), 0.5 * side, false, std::min(1.0, box.litArea / (side * side)),
            double(box.thinPoints) / box.litPoints};
}

PupilRegion bandRegion(const PupilFrame& frame, const Field& field, Sampling sampling, std::span<const LensAtWavelength> ends,
                       const std::vector<PathStep>& steps, double maxRadiusMm) {
    double xMin = 1e300, xMax = -1e300, yMin = 1e300, yMax = -1e300, litArea = 0.0, thin = 0.0;
    for (std::size_t e = 0; e < ends.size(); ++e) {
        if (e > 0 && ends[e].lambdaNm == ends[0].lambdaNm) continue; // a band of one wavelength: one search
        const PupilRegion r = pupilRegion(frame, field, sampling, ends[e], steps, maxRadiusMm);
        if (r.discOnly) continue; // paraxial sampling, or no light found at this wavelength
        xMin = std::min(xMin, r.cx - r.half), xMax = std::max(xMax, r.cx + r.half);
        yMin = std::min(yMin, r.cy - r.half), yMax = std::max(yMax, r.cy + r.half);
        litArea = std::max(litArea, r.litFraction * 4.0 * r.half * r.half);
        thin = std::max(thin, r.thinShare);
    }
    if (xMin > xMax) return {0.0, 0.0, frame.radius, true};
    const double half = 0.5 * std::max(xMax - xMin, yMax - yMin);
    return {0.5 * (xMin + xMax), 0.5 * (yMin + yMax), half, false, std::min(1.0, litArea / (4.0 * half * half)), thin};
}

Bundle regionBundle(const PupilFrame& frame, const Field& field, const PupilRegion& r, int n) {
    return gridBundle(frame, field, n, r.cx, r.cy, r.half, r.discOnly);
}

Bundle makeBundle(const PupilFrame& frame, const Field& field, Sampling sampling, int n, const LensAtWavelength& L,
                  const std::vector<PathStep>& steps) {
    return regionBundle(frame, field, pupilRegion(frame, field, sampling, L, steps), n);
}

} // namespace ff::trace
