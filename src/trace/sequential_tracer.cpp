#include "trace/sequential_tracer.h"

#include "optics/paraxial.h"
#include "optics/thin_film.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ff::trace {

using optics::RayStatus;

LensAtWavelength::LensAtWavelength(const optics::Lens& l, double lambda, double sensor, Films films)
    : lens(&l), lambdaNm(lambda) {
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
    for (std::size_t s = 0; s < n; ++s) {
        const bool homogeneous = !l.surfaces[s].medium.gradient && !(s > 0 && l.surfaces[s - 1].medium.gradient);
        const bool tabulate =
            films == Films::Tabulated && homogeneous && !layersFromLow[s].empty() && nBefore[s] != nAfter[s];
        const double lo = std::min(nBefore[s], nAfter[s]), hi = std::max(nBefore[s], nAfter[s]);
        filmFromLow.push_back(tabulate ? std::optional(optics::FilmReflectanceTable(lo, layersFromLow[s], hi, lambda))
                                       : std::nullopt);
        filmFromHigh.push_back(tabulate ? std::optional(optics::FilmReflectanceTable(hi, layersFromHigh[s], lo, lambda))
                                        : std::nullopt);
    }
    for (std::size_t s = 0; s < n; ++s) {
        const optics::Medium& m = l.surfaces[s].medium;
        gradient.push_back(m.gradient && s + 1 < n
                               ? std::optional(optics::GradientField(m.index(lambda), *m.gradient, lambda, vertexZ[s]))
                               : std::nullopt);
        barrelRadius.push_back(s + 1 < n ? std::max(clipRadius[s], clipRadius[s + 1]) : 0.0);
        gradientStep.push_back(0.0);
        if (!gradient[s]) continue;
        const double r = 0.5 * barrelRadius[s];
        const auto sag = l.surfaces[s].sagAt(r, 0.0);
        if (!sag) continue;
        const auto probe = optics::propagate(*gradient[s], {r, 0.0, vertexZ[s] + *sag}, {0.0, 0.0, 1.0}, l.surfaces[s],
                                             vertexZ[s], l.surfaces[s + 1], vertexZ[s + 1]);
        if (probe && probe->steps > 0) gradientStep.back() = probe->length / static_cast<double>(probe->steps);
    }
}

double LensAtWavelength::indexBefore(std::size_t s, const glm::dvec3& p) const {
    return s > 0 && gradient[s - 1] ? gradient[s - 1]->index(p) : nBefore[s];
}

double LensAtWavelength::indexAfter(std::size_t s, const glm::dvec3& p) const {
    return gradient[s] ? gradient[s]->index(p) : nAfter[s];
}

std::optional<optics::SurfaceHit> nextHit(const LensAtWavelength& L, std::size_t left, std::size_t s, optics::Ray& ray,
                                          bool* graded, double* opticalPath, RayStatus* status, double* barrelMargin) {
    if (status) *status = RayStatus::Missed;
    if (barrelMargin) *barrelMargin = std::numeric_limits<double>::infinity();
    // The space the ray is in: after `left` travelling forward, before it travelling back.
    std::size_t space = kObjectSpace;
    if (left != kObjectSpace) space = ray.dir.z > 0.0 ? left : (left > 0 ? left - 1 : kObjectSpace);
    if (graded) *graded = false;
    if (space == kObjectSpace || !L.gradient[space]) {
        auto hit = optics::intersectSurface(L.lens->surfaces[s], L.vertexZ[s], ray, kMinStep);
        if (hit && opticalPath) *opticalPath = hit->t * (space == kObjectSpace ? L.nBefore[0] : L.nAfter[space]);
        return hit;
    }
    if (graded) *graded = true;
    const std::size_t from = space == left ? space : space + 1, to = from == space ? space + 1 : space;
    if (s != to) return std::nullopt; // a graded element is left only through its other surface
    optics::GradientLoss loss = optics::GradientLoss::None;
    optics::GradientSettings settings = L.gradientSettings;
    if (settings.initialStep <= 0.0) settings.initialStep = L.gradientStep[space];
    const auto g = optics::propagate(*L.gradient[space], ray.origin, ray.dir, L.lens->surfaces[from], L.vertexZ[from],
                                     L.lens->surfaces[to], L.vertexZ[to], barrelMargin ? 0.0 : L.barrelRadius[space],
                                     settings, &loss);
    if (!g) {
        if (status && loss == optics::GradientLoss::Barrel) *status = RayStatus::Clipped;
        return std::nullopt;
    }
    ray.dir = g->dir;
    if (opticalPath) *opticalPath = g->opticalPath;
    if (barrelMargin && L.barrelRadius[space] > 0.0) *barrelMargin = L.barrelRadius[space] - g->maxRadius;
    return optics::SurfaceHit{g->length, g->point, g->normal};
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
    const double before = L.indexBefore(s, hit.point), after = L.indexAfter(s, hit.point);
    const double n1 = forward ? before : after;
    const double n2 = forward ? after : before;
    double R = 0.0;
    if (weighting == Weighting::Fresnel && n1 != n2) {
        const double cosI = std::min(1.0, std::abs(glm::dot(ray.dir, hit.normal)));
        // The coating sits on the glass (higher-index) side: met in spec order from the other side.
        const auto& table = n1 < n2 ? L.filmFromLow[s] : L.filmFromHigh[s];
        if (table)
            R = (*table)(cosI);
        else
            R = optics::filmReflectance(n1, n1 < n2 ? L.layersFromLow[s] : L.layersFromHigh[s], n2, cosI, L.lambdaNm);
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
    double opticalPath = 0.0;
    for (std::size_t k = 0; k < steps.size(); ++k) {
        const std::size_t s = steps[k].surface;
        RayStatus status = RayStatus::Ok;
        double segment = 0.0;
        RayStatus missed = RayStatus::Missed;
        double barrel = std::numeric_limits<double>::infinity();
        auto hit = nextHit(L, k > 0 ? steps[k - 1].surface : kObjectSpace, s, ray, nullptr, &segment, &missed,
                           openMargins ? &barrel : nullptr);
        if (k > 0) opticalPath += segment;
        if (!hit)
            status = missed;
        else if (openMargins) {
            openMargins[k] = L.apertureMargin(s, hit->point);
            double& into = s == L.stop && k > 0 ? openMargins[k - 1] : openMargins[k];
            into = std::min(into, barrel);
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
    out.opticalPath = opticalPath;
    return out;
}

} // namespace ff::trace
