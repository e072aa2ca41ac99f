#pragma once
// Traces bundles of rays along one path (direct or ghost) through the Embree scene of a lens, in
// packets of 8 (coherent context) with TBB over tiles of packets. At every path step the nearest hit
// in the whole scene must be the surface the path expects next; anything else (the iris, the barrel,
// another surface) blocks the ray. It is asked as: the exact hit on the expected surface first, then
// one occlusion query (rtcOccluded8) on the segment up to it with that surface excluded. The
// physics at a hit (refraction, reflection, Fresnel/coating weights) is trace::applyStep, shared with
// the analytic reference tracer. Results do not depend on the number of threads.

#include "trace/embree_device.h"
#include "trace/lens_scene.h"
#include "trace/sequential_tracer.h"

#include <span>

namespace ff::trace {

struct RayResult {
    optics::RayStatus status = optics::RayStatus::Ok;
    std::size_t lostAtStep = 0;
    glm::dvec3 sensorPoint{0.0}; ///< where the ray meets the sensor plane (valid when Ok)
    glm::dvec3 dir{0.0};
    double weight = 0.0; ///< product of all Fresnel/coating factors; 0 when lost
};

/// Whether a ray's landing point lies within maxRadiusMm of the axis (0: no limit).
inline bool landsWithin(const RayResult& r, double maxRadiusMm) {
    return maxRadiusMm <= 0.0 ||
           r.sensorPoint.x * r.sensorPoint.x + r.sensorPoint.y * r.sensorPoint.y <= maxRadiusMm * maxRadiusMm;
}

class EmbreeTracer {
  public:
    /// Builds the scene of L's lens (apertures, iris and stop from L; the same for every wavelength).
    explicit EmbreeTracer(const LensAtWavelength& geometry);

    /// Traces rays along steps at L's wavelength; out has one result per ray.
    void trace(const LensAtWavelength& L, const std::vector<PathStep>& steps, std::span<const optics::Ray> rays,
               std::span<RayResult> out) const;

  private:
    EmbreeDevice device_;
    LensScene scene_;
};

/// The same bundle through the analytic sequential tracer (no Embree), TBB-parallel: the reference,
/// and the baseline of the benchmarks. Weighting::None leaves every weight at 1 (fates and paths only).
void traceAnalytic(const LensAtWavelength& L, const std::vector<PathStep>& steps, std::span<const optics::Ray> rays,
                   std::span<RayResult> out, Weighting weighting = Weighting::Fresnel);

} // namespace ff::trace
