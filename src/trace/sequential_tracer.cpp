#include "trace/sequential_tracer.h"

#include "optics/paraxial.h"
#include "optics/thin_film.h"

#include <glm/geometric.hpp>

#include <cmath>

namespace ff::trace {

using optics::RayStatus;

LensAtWavelength::LensAtWavelength(const optics::Lens& l, double lambda) : lens(&l), lambdaNm(lambda) {
    const std::size_t n = l.surfaces.size();
    const std::size_t stop = l.stopIndex();
    const double stopRadius = optics::workingStopSemiAperture(l);
    double z = 0.0;
    for (std::size_t s = 0; s < n; ++s) {
        nBefore.push_back(l.mediumBefore(s).index(lambda));
        nAfter.push_back(l.surfaces[s].medium.index(lambda));
        clipRadius.push_back(s == stop ? stopRadius : l.surfaces[s].semiAperture);
        vertexZ.push_back(z);
        z += l.surfaces[s].thickness;
    }
    sensorZ = z;
}

SequentialResult traceSequential(const LensAtWavelength& L, const std::vector<PathStep>& steps, optics::Ray ray) {
    SequentialResult out;
    double weight = 1.0;
    for (std::size_t k = 0; k < steps.size(); ++k) {
        const std::size_t s = steps[k].surface;
        const optics::Surface& surf = L.lens->surfaces[s];
        auto lost = [&](RayStatus st) {
            out.status = st;
            out.lostAtStep = k;
            out.ray = ray;
            out.weight = 0.0;
            return out;
        };
        auto hit = optics::intersectSurface(surf, L.vertexZ[s], ray, 1e-9);
        if (!hit) return lost(RayStatus::Missed);
        const double r = L.clipRadius[s];
        if (r > 0.0 && hit->point.x * hit->point.x + hit->point.y * hit->point.y > r * r) return lost(RayStatus::Clipped);

        // Media on the incident and far side depend on the travel direction.
        const bool forward = ray.dir.z > 0.0;
        const double n1 = forward ? L.nBefore[s] : L.nAfter[s];
        const double n2 = forward ? L.nAfter[s] : L.nBefore[s];
        const double cosI = std::min(1.0, std::abs(glm::dot(ray.dir, hit->normal)));
        const double R = (n1 == n2) ? 0.0 : optics::coatedReflectance(L.lens->coatingOf(s), n1, n2, cosI, L.lambdaNm);
        if (steps[k].reflect) {
            weight *= R;
            ray = {hit->point, optics::reflect(ray.dir, hit->normal)};
        } else {
            auto dir = optics::refract(ray.dir, hit->normal, n1, n2);
            if (!dir) return lost(RayStatus::TotalInternalReflection);
            weight *= 1.0 - R;
            ray = {hit->point, *dir};
        }
    }
    // Carry the ray to the sensor plane.
    if (ray.dir.z <= 0.0) {
        out.status = RayStatus::Missed;
        out.lostAtStep = steps.size();
        out.ray = ray;
        return out;
    }
    const double t = (L.sensorZ - ray.origin.z) / ray.dir.z;
    out.ray = {ray.origin + t * ray.dir, ray.dir};
    out.weight = weight;
    return out;
}

} // namespace ff::trace
