#include "trace/embree_tracer.h"

#include "core/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <limits>

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

// Traces up to 8 rays [first, first + count) as one packet.
void tracePacket(RTCScene scene, const LensAtWavelength& L, const std::vector<PathStep>& steps,
                 std::span<const optics::Ray> rays, std::span<RayResult> out, std::size_t first, int count) {
    optics::Ray cur[kPacket];
    double weight[kPacket];
    bool alive[kPacket] = {};
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

    alignas(32) RTCRayHit8 rh;
    for (std::size_t k = 0; k < steps.size(); ++k) {
        alignas(32) int valid[kPacket];
        bool any = false;
        for (int i = 0; i < kPacket; ++i) {
            valid[i] = (i < count && alive[i]) ? -1 : 0;
            any = any || valid[i];
            const optics::Ray& r = cur[i];
            rh.ray.org_x[i] = static_cast<float>(r.origin.x);
            rh.ray.org_y[i] = static_cast<float>(r.origin.y);
            rh.ray.org_z[i] = static_cast<float>(r.origin.z);
            rh.ray.dir_x[i] = static_cast<float>(r.dir.x);
            rh.ray.dir_y[i] = static_cast<float>(r.dir.y);
            rh.ray.dir_z[i] = static_cast<float>(r.dir.z);
            rh.ray.tnear[i] = static_cast<float>(kMinStep);
            rh.ray.tfar[i] = std::numeric_limits<float>::infinity();
            rh.ray.time[i] = 0.0f;
            rh.ray.mask[i] = 0xFFFFFFFFu;
            rh.ray.id[i] = static_cast<unsigned>(i);
            rh.ray.flags[i] = 0;
            rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        }
        if (!any) return;
        rtcIntersect8(valid, scene, &ctx.embree, &rh);

        const std::size_t s = steps[k].surface;
        for (int i = 0; i < count; ++i) {
            if (!alive[i]) continue;
            RayResult& res = out[first + i];
            const unsigned g = rh.hit.geomID[i];
            if (g == RTC_INVALID_GEOMETRY_ID) {
                loseRay(res, RayStatus::Missed, k);
                alive[i] = false;
                continue;
            }
            if (g != s) {
                loseRay(res, RayStatus::Blocked, k);
                alive[i] = false;
                continue;
            }
            // The scene says the expected surface is first; compute the hit exactly in double.
            auto hit = optics::intersectSurface(L.lens->surfaces[s], L.vertexZ[s], cur[i], kMinStep);
            const RayStatus st = hit ? applyStep(L, steps[k], *hit, cur[i], weight[i]) : RayStatus::Missed;
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

void EmbreeTracer::trace(const LensAtWavelength& L, const std::vector<PathStep>& steps, std::span<const optics::Ray> rays,
                         std::span<RayResult> out) const {
    if (out.size() != rays.size()) throwRuntimeError("EmbreeTracer::trace: output size differs from the ray count");
    const std::size_t packets = (rays.size() + kPacket - 1) / kPacket;
    RTCScene scene = scene_.get();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, packets, kPacketsPerTask), [&](const tbb::blocked_range<std::size_t>& r) {
        setFlushDenormalsToZero();
        for (std::size_t p = r.begin(); p < r.end(); ++p) {
            const std::size_t first = p * kPacket;
            const int count = static_cast<int>(std::min<std::size_t>(kPacket, rays.size() - first));
            tracePacket(scene, L, steps, rays, out, first, count);
        }
    });
}

void traceAnalytic(const LensAtWavelength& L, const std::vector<PathStep>& steps, std::span<const optics::Ray> rays,
                   std::span<RayResult> out) {
    if (out.size() != rays.size()) throwRuntimeError("traceAnalytic: output size differs from the ray count");
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 128), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            const SequentialResult s = traceSequential(L, steps, rays[i]);
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
