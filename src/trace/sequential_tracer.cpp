#include "trace/sequential_tracer.h"

#include "optics/paraxial.h"
#include "optics/thin_film.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <numbers>

namespace ff::trace {

using optics::RayStatus;

LensAtWavelength::LensAtWavelength(const optics::Lens& l, double lambda, double sensor) : lens(&l), lambdaNm(lambda) {
    const std::size_t n = l.surfaces.size();
    stop = l.stopIndex();
    const double stopRadius = optics::workingStopSemiAperture(l);
    iris = Iris(l.apertureBlades, l.bladeRotationDeg * std::numbers::pi / 180.0, stopRadius);
    double z = 0.0;
    for (std::size_t s = 0; s < n; ++s) {
        nBefore.push_back(l.mediumBefore(s).index(lambda));
        nAfter.push_back(l.surfaces[s].medium.index(lambda));
        clipRadius.push_back(s == stop ? iris.circumradius : l.surfaces[s].semiAperture);
        layersFromLow.push_back(optics::filmLayers(l.coatingOf(s), lambda));
        layersFromHigh.emplace_back(layersFromLow.back().rbegin(), layersFromLow.back().rend());
        vertexZ.push_back(z);
        z += l.surfaces[s].thickness;
    }
    sensorZ = std::isnan(sensor) ? z : sensor;
}

bool LensAtWavelength::insideAperture(std::size_t s, const glm::dvec3& p) const {
    if (s == stop) return iris.contains(p.x, p.y);
    const double r = clipRadius[s];
    return r <= 0.0 || p.x * p.x + p.y * p.y <= r * r;
}

double LensAtWavelength::apertureMargin(std::size_t s, const glm::dvec3& p) const {
    if (s == stop) return iris.margin(p.x, p.y);
    const double r = clipRadius[s];
    return r <= 0.0 ? std::numeric_limits<double>::infinity() : r - std::hypot(p.x, p.y);
}

RayStatus applyStep(const LensAtWavelength& L, const PathStep& step, const optics::SurfaceHit& hit, optics::Ray& ray,
                    double& weight, Weighting weighting) {
    const std::size_t s = step.surface;
    // Media on the incident and far side depend on the travel direction.
    const bool forward = ray.dir.z > 0.0;
    const double n1 = forward ? L.nBefore[s] : L.nAfter[s];
    const double n2 = forward ? L.nAfter[s] : L.nBefore[s];
    double R = 0.0;
    if (weighting == Weighting::Fresnel && n1 != n2) {
        const double cosI = std::min(1.0, std::abs(glm::dot(ray.dir, hit.normal)));
        // The coating sits on the glass (higher-index) side: met in spec order from the other side.
        const auto& layers = n1 < n2 ? L.layersFromLow[s] : L.layersFromHigh[s];
        R = optics::filmReflectance(n1, layers, n2, cosI, L.lambdaNm);
    }
    if (step.reflect) {
        if (weighting == Weighting::Fresnel) weight *= R;
        ray = {hit.point, optics::reflect(ray.dir, hit.normal)};
        return RayStatus::Ok;
    }
    auto dir = optics::refract(ray.dir, hit.normal, n1, n2);
    if (!dir) return RayStatus::TotalInternalReflection;
    weight *= 1.0 - R;
    ray = {hit.point, *dir};
    return RayStatus::Ok;
}

bool toSensor(const LensAtWavelength& L, optics::Ray& ray) {
    if (ray.dir.z <= 0.0) return false;
    const double t = (L.sensorZ - ray.origin.z) / ray.dir.z;
    ray.origin += t * ray.dir;
    return true;
}

SequentialResult traceSequential(const LensAtWavelength& L, const std::vector<PathStep>& steps, optics::Ray ray,
                                 Weighting weighting, double* openMargins, glm::dvec3* openPoints) {
    SequentialResult out;
    double weight = 1.0;
    if (openMargins)
        for (std::size_t k = 0; k < steps.size(); ++k) {
            openMargins[k] = std::numeric_limits<double>::quiet_NaN();
            if (openPoints) openPoints[k] = glm::dvec3(openMargins[k]);
        }
    for (std::size_t k = 0; k < steps.size(); ++k) {
        const std::size_t s = steps[k].surface;
        RayStatus status = RayStatus::Ok;
        auto hit = optics::intersectSurface(L.lens->surfaces[s], L.vertexZ[s], ray, kMinStep);
        if (!hit)
            status = RayStatus::Missed;
        else if (openMargins) {
            openMargins[k] = L.apertureMargin(s, hit->point);
            if (openPoints) openPoints[k] = hit->point;
        } else if (!L.insideAperture(s, hit->point))
            status = RayStatus::Clipped;
        if (status == RayStatus::Ok) status = applyStep(L, steps[k], *hit, ray, weight, weighting);
        if (status != RayStatus::Ok) {
            out.status = status;
            out.lostAtStep = k;
            out.ray = ray;
            return out;
        }
    }
    if (!toSensor(L, ray)) {
        out.status = RayStatus::Missed;
        out.lostAtStep = steps.size();
        out.ray = ray;
        return out;
    }
    out.ray = ray;
    out.weight = weight;
    return out;
}

} // namespace ff::trace
