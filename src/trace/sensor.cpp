#include "trace/sensor.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/sequential_tracer.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace ff::trace {

namespace {

[[noreturn]] void unknownName(const char* what, const std::string& name, const char* names) {
    throw Error(ErrorKind::Usage,
                std::string("unknown ") + what + " " + text::quoted(name) + " (expected " + names + ")");
}

// The lens at the d line, its pupil frame and direct path: one ray of a field through a point of the
// entrance pupil's plane traced with the apertures open (where a lens vignettes its own chief ray, the
// rest of the beam still images the source there), giving its points on the stop (0 without a stop)
// and on the sensor.
struct ChiefRays {
    ChiefRays(const optics::Lens& lens, double sensorZ)
        : L(lens, lines::d, sensorZ), pupil(pupilFrame(lens)), steps(pathSteps(lens, std::nullopt)),
          stopStep(steps.size()), margins(steps.size()), points(steps.size()) {
        for (std::size_t k = 0; k < steps.size(); ++k)
            if (steps[k].surface == L.stop) stopStep = k;
    }
    bool hasStop() const { return stopStep < steps.size(); }
    std::optional<std::pair<glm::dvec3, glm::dvec3>> trace(const Field& field, double px, double py) {
        const Bundle one = gridBundle(pupil, field, 1, px, py, 1e-9, false);
        const SequentialResult s =
            traceSequential(L, steps, one.rays[0], Weighting::Fresnel, margins.data(), points.data());
        if (s.status != optics::RayStatus::Ok) return std::nullopt;
        return std::pair(hasStop() ? points[stopStep] : glm::dvec3(0.0), s.ray.origin);
    }

    const LensAtWavelength L;
    const PupilFrame pupil;
    const std::vector<PathStep> steps;
    std::size_t stopStep;
    std::vector<double> margins;
    std::vector<glm::dvec3> points;
};

// The field of an anamorphic lens (no rotational symmetry) whose chief ray lands at (x, y) mm: the
// transverse part u of its direction (|u| = sin of the field angle) and the point where it crosses
// the paraxial entrance pupil's plane solved together by Newton's method with finite-difference
// Jacobians — the inner solve aims the ray through the stop's centre, the outer moves u until the
// ray lands on the point, approached from the axis (the first step from the paraxial field of each
// section: tan = x / EFLx, y / EFLy).
Field anamorphicField(const optics::Lens& lens, double sensorZ, double xMm, double yMm) {
    ChiefRays rays(lens, sensorZ);
    const PupilFrame& pupil = rays.pupil;
    const auto fieldOf = [&](glm::dvec2 u) {
        const double s = std::min(glm::length(u), 1.0 - 1e-12);
        const glm::dvec2 e = s > 0.0 ? pupil.eflSign * u / glm::length(u) : glm::dvec2(0.0, 1.0);
        return Field{std::asin(s), std::atan2(-e.x, e.y)};
    };
    // The stop point and the sensor point of the ray of direction u through pupil point a.
    const auto trace = [&](glm::dvec2 u, glm::dvec2 a) -> std::optional<std::pair<glm::dvec2, glm::dvec2>> {
        const auto r = rays.trace(fieldOf(u), a.x, a.y);
        return r ? std::optional(std::pair(glm::dvec2(r->first), glm::dvec2(r->second))) : std::nullopt;
    };
    // Solves g(v) = target for v by Newton's method, the Jacobian by forward differences of step h.
    const auto newton = [](auto g, glm::dvec2 v, glm::dvec2 target, double h, double tolerance) {
        for (int it = 0; it < 50; ++it) {
            const auto g0 = g(v);
            if (!g0) return std::optional<glm::dvec2>();
            const glm::dvec2 residual = *g0 - target;
            if (glm::length(residual) < tolerance) return std::optional(v);
            const auto gx = g(v + glm::dvec2(h, 0.0)), gy = g(v + glm::dvec2(0.0, h));
            if (!gx || !gy) return std::optional<glm::dvec2>();
            const glm::dvec2 cx = (*gx - *g0) / h, cy = (*gy - *g0) / h;
            const double det = cx.x * cy.y - cy.x * cx.y;
            if (det == 0.0 || !std::isfinite(det)) return std::optional<glm::dvec2>();
            v -= glm::dvec2(cy.y * residual.x - cy.x * residual.y, -cx.y * residual.x + cx.x * residual.y) / det;
        }
        return std::optional<glm::dvec2>();
    };
    glm::dvec2 aim(0.0);
    const auto land = [&](glm::dvec2 u) -> std::optional<glm::dvec2> {
        if (rays.hasStop()) {
            const auto stop = [&](glm::dvec2 a) -> std::optional<glm::dvec2> {
                const auto r = trace(u, a);
                return r ? std::optional(r->first) : std::nullopt;
            };
            const auto a = newton(stop, aim, glm::dvec2(0.0), 1e-4 * pupil.radius, 1e-10);
            if (!a) return std::nullopt;
            aim = *a; // the next solve starts from this one
        }
        const auto r = trace(u, aim);
        return r ? std::optional(r->second) : std::nullopt;
    };
    const double fy = std::abs(optics::paraxialEfl(optics::sectionOf(lens, optics::Section::Y), lines::d));
    const double fx = std::abs(optics::paraxialEfl(optics::sectionOf(lens, optics::Section::X), lines::d));
    // Continuation: the point approached in eight steps from the axis, each solve starting from the
    // last one's field and aim (the paraxial guess alone leaves far fields' rays vignetted).
    const glm::dvec2 target(xMm, yMm);
    std::optional<glm::dvec2> u = glm::dvec2(0.0);
    constexpr int kSteps = 8;
    for (int k = 1; k <= kSteps && u; ++k) {
        const glm::dvec2 point = target * (double(k) / kSteps);
        const glm::dvec3 guess = glm::normalize(glm::dvec3(point.x / fx, point.y / fy, 1.0));
        const glm::dvec2 start = k == 1 ? pupil.eflSign * glm::dvec2(guess) : *u;
        u = newton(land, start, point, 1e-7, 1e-9 * (1.0 + glm::length(point)));
    }
    if (!u || glm::length(*u) >= 1.0)
        throw Error(ErrorKind::Input, "no field images a source at (" + text::fixed(xMm, 3) + ", " +
                                          text::fixed(yMm, 3) +
                                          ") mm on the sensor (the chief ray does not reach it); is the light outside "
                                          "the lens's field?");
    return fieldOf(*u);
}

} // namespace

Sampling samplingNamed(const std::string& name) {
    if (name == "reaim") return Sampling::Reaim;
    if (name == "paraxial-grid") return Sampling::ParaxialGrid;
    unknownName("sampling", name, "reaim or paraxial-grid");
}

SensorPlane sensorPlaneNamed(const std::string& name) {
    if (name == "file") return SensorPlane::File;
    if (name == "paraxial") return SensorPlane::Paraxial;
    unknownName("sensor plane", name, "file or paraxial");
}

CoatingChoice coatingNamed(const std::string& name) {
    if (name == "file") return CoatingChoice::File;
    if (name == "none") return CoatingChoice::None;
    if (name == "mgf2") return CoatingChoice::MgF2;
    unknownName("coating", name, "file, none or mgf2");
}

double sensorPlaneZ(const optics::Lens& lens, SensorPlane plane) {
    if (plane == SensorPlane::File) return lens.sensorZ();
    return lens.vertexZ(lens.surfaces.size() - 1) + optics::paraxialBfd(lens, lines::d);
}

optics::Lens withCoating(const optics::Lens& lens, CoatingChoice choice) {
    optics::Lens out = lens;
    if (choice == CoatingChoice::File) return out;
    for (std::size_t s = 0; s < out.surfaces.size(); ++s) {
        const bool glassAir = out.mediumBefore(s).isAir() != out.surfaces[s].medium.isAir();
        out.surfaces[s].coating = (choice == CoatingChoice::MgF2 && glassAir) ? optics::CoatingSpec::mgf2(550.0)
                                                                              : optics::CoatingSpec::none();
    }
    return out;
}

Field fieldForSensorPoint(const optics::Lens& lens, double sensorZ, double xMm, double yMm) {
    if (!lens.rotationallySymmetric()) return anamorphicField(lens, sensorZ, xMm, yMm);
    const double r = std::sqrt(xMm * xMm + yMm * yMm);
    Field f;
    f.azimuthRad = std::atan2(-xMm, yMm); // image at r (-sin az, cos az)
    if (r == 0.0) return f;
    ChiefRays rays(lens, sensorZ);
    const PupilFrame& pupil = rays.pupil;
    // Height of the chief ray on the sensor for a field angle (azimuth 0: image along +y): the ray
    // of that field through the centre of the stop (aimed by the secant method from the paraxial
    // entrance pupil's centre, where wide-angle lenses' pupils have moved).
    auto trace = [&](double theta, double py) -> std::optional<std::pair<double, double>> {
        const auto hit = rays.trace({theta, 0.0}, 0.0, py);
        return hit ? std::optional(std::make_pair(hit->first.y, hit->second.y)) : std::nullopt;
    };
    auto height = [&](double theta) -> std::optional<double> {
        // Start from the paraxial pupil's centre, else from the traced point of the pupil nearest it.
        const double h = searchHalfSize(pupil, {theta, 0.0});
        double p0 = 0.0;
        auto r0 = trace(theta, p0);
        for (int k = 1; k <= 32 && !r0; ++k)
            for (const double sign : {-1.0, 1.0})
                if (!r0) r0 = trace(theta, p0 = sign * h * k / 32.0);
        if (!r0) return std::nullopt;
        double p1 = p0 + 1e-3 * h;
        for (int it = 0; it < 40 && rays.hasStop(); ++it) {
            if (std::abs(r0->first) < 1e-10) break;
            const auto r1 = trace(theta, p1);
            if (!r1 || r1->first == r0->first) return std::nullopt;
            const double next = p1 - r1->first * (p1 - p0) / (r1->first - r0->first);
            p0 = p1, r0 = r1, p1 = next;
        }
        if (rays.hasStop() && !(std::abs(r0->first) < 1e-6)) return std::nullopt;
        return r0->second;
    };
    // Bisection on the angle; the image height grows monotonically with it for a photographic lens.
    double lo = 0.0, hi = degToRad(89.0);
    for (int it = 0; it < 100 && hi - lo > 1e-13; ++it) {
        const double mid = 0.5 * (lo + hi);
        const auto h = height(mid);
        if (h && *h < r)
            lo = mid;
        else
            hi = mid;
    }
    const auto reached = height(lo);
    if (!reached || std::abs(*reached - r) > 1e-6 * (1.0 + r))
        throw Error(ErrorKind::Input,
                    "no field angle images a source at " + text::fixed(r, 3) +
                        " mm from the axis (the chief ray does not reach it); is the light outside the lens's field?");
    f.angleRad = lo;
    return f;
}

double sensorCornerFieldDeg(const optics::Lens& lens, double sensorZ, std::pair<double, double> sensorMm) {
    const double reach = 0.5 * std::hypot(sensorMm.first, sensorMm.second) * 1.05;
    try {
        return radToDeg(fieldForSensorPoint(lens, sensorZ, 0.0, reach).angleRad);
    } catch (const Error&) {
        return std::min(80.0, radToDeg(std::atan(reach / std::abs(optics::paraxialEfl(lens, lines::d)))));
    }
}

} // namespace ff::trace
