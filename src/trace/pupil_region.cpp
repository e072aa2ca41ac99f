#include "trace/pupil_region.h"

#include <algorithm>
#include <cmath>

namespace ff::trace {

double searchHalfSize(const PupilFrame& frame, const Field& field) {
    const double shift = std::abs(std::tan(field.angleRad)) * std::abs(frame.z - frame.startZ);
    return std::max(frame.frontRadius, frame.radius) + shift + frame.radius;
}

Bundle regionBundle(const PupilFrame& frame, const Field& field, const PupilRegion& r, int n) {
    return gridBundle(frame, field, n, r.cx, r.cy, r.half, r.discOnly);
}

} // namespace ff::trace
