#pragma once
// The Embree scene of a lens: every optical surface as a user geometry with exact analytic
// intersection (never tessellated) clipped to its clear aperture; the iris as a plane in the stop's
// vertex plane that is solid outside the blade polygon, where the stop is flat (a stop on a curved
// surface is that surface, clipped by the blade polygon at the hit point); the barrel as a cylinder
// between consecutive surfaces, radius the larger of their clear apertures. Geometry IDs: surface k has ID k; the iris
// and barrel pieces follow.
//
// Precision: Embree traverses with float rays, but the callbacks intersect the double-precision ray
// carried in the query context (QueryContext), so the scene decides *what* is in the way while hit
// points are computed in double by the same code as the analytic reference tracer. Both intersection
// (nearest hit) and occlusion (any hit on a segment) queries are supported; a per-ray geometry ID in
// the context is ignored, so a segment can end on the surface it is aimed at.

#include "optics/real_ray.h"
#include "trace/embree_device.h"
#include "trace/sequential_tracer.h"

#include <embree3/rtcore.h>

#include <memory>
#include <vector>

namespace ff::trace {

/// Per-query data reaching the callbacks: must begin with the Embree context.
struct QueryContext {
    RTCIntersectContext embree;
    const optics::Ray* rays = nullptr; ///< double rays, indexed by the Embree ray id
    const unsigned* ignore = nullptr;  ///< per ray id: a geometry ID that never counts (or null)
};

class LensScene {
  public:
    /// Builds the scene of the lens at its active zoom position (aperture shapes from `geometry`).
    LensScene(EmbreeDevice& device, const LensAtWavelength& geometry);
    ~LensScene();
    LensScene(const LensScene&) = delete;
    LensScene& operator=(const LensScene&) = delete;

    RTCScene get() const { return scene_; }

    struct SurfacePrim;
    struct IrisPrim;
    struct BarrelPrim;

  private:
    RTCScene scene_ = nullptr;
    std::size_t surfaceCount_ = 0;
    std::vector<std::unique_ptr<SurfacePrim>> surfaces_;
    std::unique_ptr<IrisPrim> iris_;
    std::vector<std::unique_ptr<BarrelPrim>> barrel_;
};

} // namespace ff::trace
