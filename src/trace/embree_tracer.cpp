#include "trace/embree_tracer.h"

#include "core/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <limits>
#include <optional>

namespace ff::trace {

using optics::RayStatus;

namespace {

constexpr int kPacket = 8;
constexpr std::size_t kPacketsPerTask = 16;

void loseRay(RayResult& r, RayStatus status, std::size_t step) {
    r.status = status;
    r.lostAtStep = step;
    r.weight = 0.0;
}

// Traces up to 8 rays [first, first + count) as one packet. At each step the exact hit on the
// expected surface is computed first (a miss, a hit outside its aperture or total internal reflection
// loses the ray as in the analytic tracer); then one occlusion query asks Embree whether anything
// else in the scene lies on the segment from the ray's origin to that hit. If so the ray is blocked:
// the nearest hit in the scene was not the surface the path expects. A curved path through a graded
// element is followed by nextHit, which checks the element's barrel itself.
void tracePacket(RTCScene scene, const LensAtWavelength& L, const std::vector<PathStep>& steps,
                 std::span<const optics::Ray> rays, std::span<RayResult> out, std::size_t first, int count) {
    optics::Ray cur[kPacket];
    double weight[kPacket];
    bool alive[kPacket] = {};
    unsigned expected[kPacket] = {};
    std::optional<optics::SurfaceHit> hit[kPacket];
    for (int i = 0; i < count; ++i) {
        cur[i] = rays[first + i];
        weight[i] = 1.0;
        alive[i] = true;
        out[first + i] = RayResult{};
    }
    QueryContext ctx;
    rtcInitIntersectContext(&ctx.embree);
    ctx.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    ctx.rays = cur;
    ctx.ignore = expected;

    alignas(32) RTCRay8 ray;
    for (std::size_t k = 0; k < steps.size(); ++k) {
        const std::size_t s = steps[k].surface;
        alignas(32) int valid[kPacket];
        bool any = false;
        for (int i = 0; i < kPacket; ++i) {
            valid[i] = 0;
            if (i >= count || !alive[i]) continue;
            bool graded = false;
            RayStatus missed = RayStatus::Missed;
            hit[i] = nextHit(L, k > 0 ? steps[k - 1].surface : kObjectSpace, s, cur[i], &graded, nullptr, &missed);
            RayResult& res = out[first + i];
            if (!hit[i])
                loseRay(res, missed, k);
            else if (!L.insideAperture(s, hit[i]->point))
                loseRay(res, RayStatus::Clipped, k);
            else if (graded) {
                // Inside a graded element nothing but its barrel (checked on the way) can block.
                const RayStatus st = applyStep(L, steps[k], *hit[i], cur[i], weight[i]);
                if (st == RayStatus::Ok) continue;
                loseRay(res, st, k);
            } else {
                valid[i] = -1;
                any = true;
                expected[i] = static_cast<unsigned>(s);
                const optics::Ray& r = cur[i];
                ray.org_x[i] = static_cast<float>(r.origin.x);
                ray.org_y[i] = static_cast<float>(r.origin.y);
                ray.org_z[i] = static_cast<float>(r.origin.z);
                ray.dir_x[i] = static_cast<float>(r.dir.x);
                ray.dir_y[i] = static_cast<float>(r.dir.y);
                ray.dir_z[i] = static_cast<float>(r.dir.z);
                ray.tnear[i] = static_cast<float>(kMinStep);
                ray.tfar[i] = static_cast<float>(hit[i]->t);
                ray.time[i] = 0.0f;
                ray.mask[i] = 0xFFFFFFFFu;
                ray.id[i] = static_cast<unsigned>(i);
                ray.flags[i] = 0;
                continue;
            }
            alive[i] = false;
        }
        if (!any) continue; // none to test against the scene at this step
        rtcOccluded8(valid, scene, &ctx.embree, &ray);
        for (int i = 0; i < count; ++i) {
            if (!valid[i]) continue;
            RayResult& res = out[first + i];
            if (ray.tfar[i] < 0.0f) { // something else came first
                loseRay(res, RayStatus::Blocked, k);
                alive[i] = false;
                continue;
            }
            const RayStatus st = applyStep(L, steps[k], *hit[i], cur[i], weight[i]);
            if (st != RayStatus::Ok) {
                loseRay(res, st, k);
                alive[i] = false;
            }
        }
    }
    for (int i = 0; i < count; ++i) {
        if (!alive[i]) continue;
        RayResult& res = out[first + i];
        if (!toSensor(L, cur[i])) {
            loseRay(res, RayStatus::Missed, steps.size());
            continue;
        }
        res.status = RayStatus::Ok;
        res.sensorPoint = cur[i].origin;
        res.dir = cur[i].dir;
        res.weight = weight[i];
    }
}

} // namespace

EmbreeTracer::EmbreeTracer(const LensAtWavelength& geometry) : device_(), scene_(device_, geometry) {}

void EmbreeTracer::trace(const LensAtWavelength& L, const std::vector<PathStep>& steps,
                         std::span<const optics::Ray> rays, std::span<RayResult> out) const {
    if (out.size() != rays.size()) throwRuntimeError("EmbreeTracer::trace: output size differs from the ray count");
    const std::size_t packets = (rays.size() + kPacket - 1) / kPacket;
    RTCScene scene = scene_.get();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, packets, kPacketsPerTask),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          setFlushDenormalsToZero();
                          for (std::size_t p = r.begin(); p < r.end(); ++p) {
                              const std::size_t first = p * kPacket;
                              const int count = static_cast<int>(std::min<std::size_t>(kPacket, rays.size() - first));
                              tracePacket(scene, L, steps, rays, out, first, count);
                          }
                      });
}

void traceAnalytic(const LensAtWavelength& L, const std::vector<PathStep>& steps, std::span<const optics::Ray> rays,
                   std::span<RayResult> out, Weighting weighting) {
    if (out.size() != rays.size()) throwRuntimeError("traceAnalytic: output size differs from the ray count");
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 128),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i < r.end(); ++i) {
                              const SequentialResult s = traceSequential(L, steps, rays[i], weighting);
                              RayResult& res = out[i];
                              res.status = s.status;
                              res.lostAtStep = s.lostAtStep;
                              res.weight = s.weight;
                              res.sensorPoint = s.status == RayStatus::Ok ? s.ray.origin : glm::dvec3(0.0);
                              res.dir = s.ray.dir;
                          }
                      });
}

} // namespace ff::trace
