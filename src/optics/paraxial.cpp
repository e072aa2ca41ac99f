#include "optics/paraxial.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "optics/gradient_index.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ff::optics {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The index on the axis at z (mm) from the vertex of the surface the medium follows: n0, plus a
// gradient's axial part.
double axialIndex(const Medium& m, double lambdaNm, double z) {
    return m.gradient ? GradientField(m.index(lambdaNm), *m.gradient, lambdaNm, 0.0).index({0.0, 0.0, z})
                      : m.index(lambdaNm);
}

// Refracts at surface i: w' = w - y c (n' - n), the indices on the axis at the vertex.
ParaxialRay refract(const Lens& lens, double lambdaNm, std::size_t i, ParaxialRay r) {
    const double n1 = i == 0 ? lens.mediumBefore(0).index(lambdaNm)
                             : axialIndex(lens.surfaces[i - 1].medium, lambdaNm, lens.surfaces[i - 1].thickness);
    const double n2 = lens.surfaces[i].medium.index(lambdaNm);
    r.w -= r.y * lens.surfaces[i].curvatureY() * (n2 - n1);
    return r;
}

// Carries the ray `distance` mm through the medium after surface i: y += t w / n in a homogeneous
// one; through a gradient the paraxial ray equation d/dz (n(z) y') = 2 a_1 y (n(z) on the axis,
// a_1 the r^2 coefficient), i.e. dy/dz = w / n(z), dw/dz = 2 a_1 y, by RK4 in steps of at most
// 0.02 mm (at least 64, at most 2^20).
ParaxialRay transfer(const Lens& lens, double lambdaNm, std::size_t i, ParaxialRay r, double distance) {
    const Medium& m = lens.surfaces[i].medium;
    if (!m.gradient) {
        r.y += distance * r.w / m.index(lambdaNm);
        return r;
    }
    const GradientField field(m.index(lambdaNm), *m.gradient, lambdaNm, 0.0);
    const double twoA1 = m.gradient->radial.empty() ? 0.0 : 2.0 * m.gradient->radial[0].at(lambdaNm);
    // Counted in double, then bounded: a graded element kilometres long takes 2^20 steps, not an
    // integer overflow or billions of them.
    const int steps = static_cast<int>(std::clamp(std::ceil(std::abs(distance) / 0.02), 64.0, 1048576.0));
    const double h = distance / steps;
    const auto slope = [&](double z, double y, double w) {
        return std::array<double, 2>{w / field.index({0.0, 0.0, z}), twoA1 * y};
    };
    for (int k = 0; k < steps; ++k) {
        const double z = k * h;
        const auto k1 = slope(z, r.y, r.w);
        const auto k2 = slope(z + h / 2, r.y + h / 2 * k1[0], r.w + h / 2 * k1[1]);
        const auto k3 = slope(z + h / 2, r.y + h / 2 * k2[0], r.w + h / 2 * k2[1]);
        const auto k4 = slope(z + h, r.y + h * k3[0], r.w + h * k3[1]);
        r.y += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]);
        r.w += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]);
    }
    return r;
}

} // namespace

ParaxialRay traceParaxial(const Lens& lens, double lambdaNm, ParaxialRay r, std::size_t from, std::size_t to) {
    for (std::size_t i = from; i < to; ++i) {
        r = refract(lens, lambdaNm, i, r);
        if (i + 1 < to) r = transfer(lens, lambdaNm, i, r, lens.surfaces[i].thickness);
    }
    return r;
}

double heightAt(const Lens& lens, double lambdaNm, ParaxialRay in, std::size_t from, std::size_t at) {
    if (at == from) return in.y;
    const ParaxialRay r = traceParaxial(lens, lambdaNm, in, from, at);
    return transfer(lens, lambdaNm, at - 1, r, lens.surfaces[at - 1].thickness).y;
}

double paraxialEfl(const Lens& lens, double lambdaNm) {
    const ParaxialRay out = traceParaxial(lens, lambdaNm, {1.0, 0.0}, 0, lens.surfaces.size());
    if (std::abs(out.w) < 1e-15)
        throw Error(ErrorKind::Input, SourceLocation{lens.file},
                    "the lens is afocal (zero power): it has no focal length");
    return -1.0 / out.w;
}

double squeeze(const Lens& lens, double lambdaNm) {
    if (lens.rotationallySymmetric()) return 1.0;
    return paraxialEfl(sectionOf(lens, Section::Y), lambdaNm) / paraxialEfl(sectionOf(lens, Section::X), lambdaNm);
}

double paraxialBfd(const Lens& lens, double lambdaNm) {
    const ParaxialRay out = traceParaxial(lens, lambdaNm, {1.0, 0.0}, 0, lens.surfaces.size());
    if (std::abs(out.w) < 1e-15)
        throw Error(ErrorKind::Input, SourceLocation{lens.file},
                    "the lens is afocal (zero power): it has no back focus");
    const double nImage = lens.surfaces.back().medium.index(lambdaNm);
    return -out.y * nImage / out.w;
}

double workingStopSemiAperture(const Lens& lens, bool* clamped) {
    if (clamped) *clamped = false;
    const std::size_t s = lens.stopIndex();
    const double physical = lens.surfaces[s].semiAperture;
    if (!lens.fNumber) {
        if (physical <= 0.0)
            throw Error(ErrorKind::Input, lens.surfaces[s].origin,
                        "the stop has no semi-aperture (0) and the header gives no 'f_number:'; "
                        "give one of them to set the aperture");
        return physical;
    }
    // EPD = 2 r / |yA|, with yA the stop height of a unit-height axial ray; EPD = EFL / N.
    const double yA = heightAt(lens, lines::d, {1.0, 0.0}, 0, s);
    const double epd = std::abs(paraxialEfl(lens, lines::d)) / *lens.fNumber;
    const double r = 0.5 * epd * std::abs(yA);
    if (physical > 0.0 && r > physical) {
        if (clamped) *clamped = true;
        return physical;
    }
    return r;
}

FirstOrder analyzeFirstOrder(const Lens& lens, double lambdaNm, bool allowAfocal) {
    FirstOrder f;
    f.lambdaNm = lambdaNm;
    const std::size_t nS = lens.surfaces.size();
    const double n0 = lens.mediumBefore(0).index(lambdaNm);
    const double nImage = lens.surfaces.back().medium.index(lambdaNm);

    // Two base rays in object space at the first vertex: A (y = 1, w = 0), B (y = 0, w = 1).
    const ParaxialRay a = traceParaxial(lens, lambdaNm, {1.0, 0.0}, 0, nS);
    const ParaxialRay b = traceParaxial(lens, lambdaNm, {0.0, 1.0}, 0, nS);
    f.afocal = std::abs(a.w) < 1e-15;
    if (f.afocal && !allowAfocal)
        throw Error(ErrorKind::Input, SourceLocation{lens.file}, "the lens is afocal (zero power)");
    if (f.afocal) {
        // A parallel beam leaves parallel; B's angle out over its angle in: u' / u = (wB / n') / (1 / n0).
        f.efl = f.bfd = f.ffd = kInf;
        f.angularMagnification = b.w * n0 / nImage;
    } else {
        f.efl = -1.0 / a.w;
        f.bfd = -a.y * nImage / a.w;
        // The ray a A + b B leaves parallel when a wA + b wB = 0, e.g. a = wB, b = -wA. In object
        // space it has y0 = a, u0 = b / n0 and crosses the axis at z_F = -y0 / u0 = n0 wB / wA.
        f.ffd = -(n0 * b.w / a.w);
    }

    // Entrance pupil: object-space rays through the stop centre satisfy a yA_s + b yB_s = 0.
    const std::size_t s = lens.stopIndex();
    const double yAs = heightAt(lens, lambdaNm, {1.0, 0.0}, 0, s);
    const double yBs = heightAt(lens, lambdaNm, {0.0, 1.0}, 0, s);
    f.stopSemiAperture = workingStopSemiAperture(lens);
    f.entrancePupilZ = (s == 0) ? 0.0 : n0 * yBs / yAs;
    f.entrancePupilDiameter = 2.0 * f.stopSemiAperture / std::abs(yAs);
    f.fNumber = std::abs(f.efl) / f.entrancePupilDiameter;

    // Exit pupil: image of the stop through surfaces s..end. C leaves the stop centre at an angle,
    // D leaves the stop edge parallel to the axis; XP is where C crosses the axis in image space.
    const ParaxialRay c = traceParaxial(lens, lambdaNm, {0.0, 1.0}, s, nS);
    const ParaxialRay d = traceParaxial(lens, lambdaNm, {f.stopSemiAperture, 0.0}, s, nS);
    if (std::abs(c.w) < 1e-15) {
        f.exitPupilZ = kInf;
        f.exitPupilDiameter = kInf;
    } else {
        f.exitPupilZ = -c.y * nImage / c.w;
        f.exitPupilDiameter = 2.0 * std::abs(d.y + f.exitPupilZ * d.w / nImage);
    }

    f.imageDistance = lens.surfaces.back().thickness;
    f.totalTrack = lens.sensorZ();
    f.reflectingInterfaces = lens.reflectingInterfaces(lambdaNm).size();
    f.ghostCount = f.reflectingInterfaces * (f.reflectingInterfaces - (f.reflectingInterfaces > 0 ? 1 : 0)) / 2;
    return f;
}

void focusAtParaxialImage(Lens& lens) {
    lens.surfaces.back().thickness = paraxialBfd(lens, lines::d);
}

Lens sectionOf(const Lens& lens, Section section) {
    Lens out = lens;
    for (Surface& s : out.surfaces) {
        if (s.rotationallySymmetric()) continue;
        const double c = section == Section::X ? s.curvatureX() : s.curvatureY();
        s.conic = section == Section::X ? s.conicOfX() : s.conicOfY();
        s.radius = c == 0.0 ? 0.0 : 1.0 / c;
        s.shape = SurfaceShape::Spherical;
        s.radiusX = s.conicX = s.radiusY = 0.0;
    }
    return out;
}

} // namespace ff::optics
