#include "trace/bundle.h"

#include "core/units.h"
#include "optics/paraxial.h"

#include <algorithm>
#include <cmath>

namespace ff::trace {

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
    // In front of the first surface's rim (its lowest point).
    const double rim =
        first.semiAperture > 0.0 ? first.rimRange(first.semiAperture).value_or(std::pair(0.0, 0.0)).first : 0.0;
    p.startZ = std::min(0.0, rim) - 1.0;
    return p;
}

Bundle gridBundle(const PupilFrame& frame, const Field& field, int n, double cx, double cy, double halfSize,
                  bool discOnly) {
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

} // namespace ff::trace
