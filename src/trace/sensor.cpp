#include "trace/sensor.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/sequential_tracer.h"

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
    const double r = std::sqrt(xMm * xMm + yMm * yMm);
    Field f;
    f.azimuthRad = std::atan2(-xMm, yMm); // image at r (-sin az, cos az)
    if (r == 0.0) return f;
    const LensAtWavelength L(lens, lines::d, sensorZ);
    const PupilFrame pupil = pupilFrame(lens);
    const auto steps = pathSteps(lens, std::nullopt);
    // Height of the chief ray on the sensor for a field angle (azimuth 0: image along +y): the ray
    // of that field through the centre of the stop (aimed by the secant method from the paraxial
    // entrance pupil's centre, where wide-angle lenses' pupils have moved), traced with the
    // apertures open: where the lens vignettes its own chief ray, the rest of the beam still images
    // the source there.
    std::size_t stopStep = steps.size();
    for (std::size_t k = 0; k < steps.size(); ++k)
        if (steps[k].surface == L.stop) stopStep = k;
    std::vector<double> margins(steps.size());
    std::vector<glm::dvec3> points(steps.size());
    auto trace = [&](double theta, double py) -> std::optional<std::pair<double, double>> {
        const Bundle one = gridBundle(pupil, {theta, 0.0}, 1, 0.0, py, 1e-9, false);
        const SequentialResult s =
            traceSequential(L, steps, one.rays[0], Weighting::Fresnel, margins.data(), points.data());
        if (s.status != optics::RayStatus::Ok) return std::nullopt;
        return std::make_pair(stopStep < steps.size() ? points[stopStep].y : 0.0, s.ray.origin.y);
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
        for (int it = 0; it < 40 && stopStep < steps.size(); ++it) {
            if (std::abs(r0->first) < 1e-10) break;
            const auto r1 = trace(theta, p1);
            if (!r1 || r1->first == r0->first) return std::nullopt;
            const double next = p1 - r1->first * (p1 - p0) / (r1->first - r0->first);
            p0 = p1, r0 = r1, p1 = next;
        }
        if (stopStep < steps.size() && !(std::abs(r0->first) < 1e-6)) return std::nullopt;
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
