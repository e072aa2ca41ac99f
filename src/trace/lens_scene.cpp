#include "trace/lens_scene.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace ff::trace {

struct LensScene::SurfacePrim {
    optics::Surface surface;
    double vertexZ = 0.0;
    double radius = 0.0; ///< clear aperture used for clipping (0 = unclipped) and bounds
    double boundsRadius = 0.0;
    bool isStop = false;
    Iris iris;

    bool inside(const glm::dvec3& p) const {
        if (isStop) return iris.contains(p.x, p.y);
        return radius <= 0.0 || p.x * p.x + p.y * p.y <= radius * radius;
    }
};

struct LensScene::IrisPrim {
    double z = 0.0;
    double outerRadius = 0.0;
    Iris iris;
};

struct LensScene::BarrelPrim {
    double radius = 0.0, z0 = 0.0, z1 = 0.0;
};

namespace {

const QueryContext& context(RTCIntersectContext* c) {
    return *reinterpret_cast<const QueryContext*>(c);
}

bool ignored(const QueryContext& ctx, unsigned rayId, unsigned geomID) {
    return ctx.ignore && ctx.ignore[rayId] == geomID;
}

// Records a hit at parameter t if it is nearer than the ray's current tfar. Ng is left zero: callers
// compute normals in double precision from the surface they asked about.
void recordHit(const RTCIntersectFunctionNArguments* args, RTCRayN* rays, RTCHitN* hits, unsigned i, double t) {
    const unsigned N = args->N;
    if (!(t < static_cast<double>(RTCRayN_tfar(rays, N, i)))) return;
    RTCRayN_tfar(rays, N, i) = static_cast<float>(t);
    RTCHitN_Ng_x(hits, N, i) = 0.0f;
    RTCHitN_Ng_y(hits, N, i) = 0.0f;
    RTCHitN_Ng_z(hits, N, i) = 0.0f;
    RTCHitN_u(hits, N, i) = 0.0f;
    RTCHitN_v(hits, N, i) = 0.0f;
    RTCHitN_primID(hits, N, i) = args->primID;
    RTCHitN_geomID(hits, N, i) = args->geomID;
    RTCHitN_instID(hits, N, i, 0) = args->context->instID[0];
}

// The three primitive kinds, each as "parameter of the first hit beyond tnear, if any".
std::optional<double> surfaceHitT(const LensScene::SurfacePrim& p, const optics::Ray& r, double tnear, double) {
    auto hit = optics::intersectSurfacePoint(p.surface, p.vertexZ, r, tnear);
    if (hit && p.inside(hit->point)) return hit->t;
    return std::nullopt;
}

std::optional<double> irisHitT(const LensScene::IrisPrim& p, const optics::Ray& r, double tnear, double) {
    if (r.dir.z == 0.0) return std::nullopt;
    const double t = (p.z - r.origin.z) / r.dir.z;
    if (!(t > tnear)) return std::nullopt;
    const double x = r.origin.x + t * r.dir.x, y = r.origin.y + t * r.dir.y;
    if (p.iris.contains(x, y) || x * x + y * y > p.outerRadius * p.outerRadius)
        return std::nullopt; // open, or outside the barrel
    return t;
}

std::optional<double> barrelHitT(const LensScene::BarrelPrim& p, const optics::Ray& r, double tnear, double tfar) {
    // A segment whose two ends are inside the tube stays inside it (the cylinder is convex).
    const double R2 = p.radius * p.radius;
    if (std::isfinite(tfar)) {
        const glm::dvec3 a = r.origin + tnear * r.dir, b = r.origin + tfar * r.dir;
        if (a.x * a.x + a.y * a.y < R2 && b.x * b.x + b.y * b.y < R2) return std::nullopt;
    }
    // (ox + t dx)^2 + (oy + t dy)^2 = R^2, between the two rims.
    const double a = r.dir.x * r.dir.x + r.dir.y * r.dir.y;
    if (a < 1e-18) return std::nullopt;
    const double b = r.origin.x * r.dir.x + r.origin.y * r.dir.y;
    const double c = r.origin.x * r.origin.x + r.origin.y * r.origin.y - p.radius * p.radius;
    const double disc = b * b - a * c;
    if (disc < 0.0) return std::nullopt;
    for (double t : {(-b - std::sqrt(disc)) / a, (-b + std::sqrt(disc)) / a}) {
        const double z = r.origin.z + t * r.dir.z;
        if (t > tnear && z >= p.z0 && z <= p.z1) return t;
    }
    return std::nullopt;
}

// Generic N-wide callbacks over a primitive kind's hit function.
template <typename Prim, std::optional<double> (*HitT)(const Prim&, const optics::Ray&, double, double)>
void intersectN(const RTCIntersectFunctionNArguments* args) {
    const auto* p = static_cast<const Prim*>(args->geometryUserPtr);
    RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
    RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, args->N);
    const QueryContext& ctx = context(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const unsigned id = RTCRayN_id(rays, args->N, i);
        if (ignored(ctx, id, args->geomID)) continue;
        if (auto t = HitT(*p, ctx.rays[id], RTCRayN_tnear(rays, args->N, i), RTCRayN_tfar(rays, args->N, i)))
            recordHit(args, rays, hits, i, *t);
    }
}

template <typename Prim, std::optional<double> (*HitT)(const Prim&, const optics::Ray&, double, double)>
void occludedN(const RTCOccludedFunctionNArguments* args) {
    const auto* p = static_cast<const Prim*>(args->geometryUserPtr);
    const QueryContext& ctx = context(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const unsigned id = RTCRayN_id(args->ray, args->N, i);
        if (ignored(ctx, id, args->geomID)) continue;
        auto t = HitT(*p, ctx.rays[id], RTCRayN_tnear(args->ray, args->N, i), RTCRayN_tfar(args->ray, args->N, i));
        if (t && *t < static_cast<double>(RTCRayN_tfar(args->ray, args->N, i)))
            RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity(); // occluded
    }
}

void surfaceBounds(const RTCBoundsFunctionArguments* args) {
    const auto* p = static_cast<const LensScene::SurfacePrim*>(args->geometryUserPtr);
    // z extent from the sag sampled over the aperture (Surface::sagRange), padded so float
    // traversal never culls a hit the double-precision callback would find.
    const auto range = p->surface.sagRange(p->boundsRadius);
    const double zMin = range ? std::min(range->first, 0.0) : 0.0, zMax = range ? std::max(range->second, 0.0) : 0.0;
    const double pad = 1e-3 + 1e-5 * p->boundsRadius;
    RTCBounds* b = args->bounds_o;
    b->lower_x = static_cast<float>(-p->boundsRadius - pad);
    b->lower_y = static_cast<float>(-p->boundsRadius - pad);
    b->lower_z = static_cast<float>(p->vertexZ + zMin - pad);
    b->upper_x = static_cast<float>(p->boundsRadius + pad);
    b->upper_y = static_cast<float>(p->boundsRadius + pad);
    b->upper_z = static_cast<float>(p->vertexZ + zMax + pad);
}

void irisBounds(const RTCBoundsFunctionArguments* args) {
    const auto* p = static_cast<const LensScene::IrisPrim*>(args->geometryUserPtr);
    const float r = static_cast<float>(p->outerRadius), z = static_cast<float>(p->z);
    *args->bounds_o = RTCBounds{-r, -r, z - 1e-3f, 0.0f, r, r, z + 1e-3f, 0.0f};
}

void barrelBounds(const RTCBoundsFunctionArguments* args) {
    const auto* p = static_cast<const LensScene::BarrelPrim*>(args->geometryUserPtr);
    const float r = static_cast<float>(p->radius) + 1e-3f;
    *args->bounds_o =
        RTCBounds{-r, -r, static_cast<float>(p->z0) - 1e-3f, 0.0f, r, r, static_cast<float>(p->z1) + 1e-3f, 0.0f};
}

RTCGeometry newUserGeometry(EmbreeDevice& device, void* user, RTCBoundsFunction bounds, RTCIntersectFunctionN intersect,
                            RTCOccludedFunctionN occluded) {
    RTCGeometry g = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, 1);
    rtcSetGeometryUserData(g, user);
    rtcSetGeometryBoundsFunction(g, bounds, nullptr);
    rtcSetGeometryIntersectFunction(g, intersect);
    rtcSetGeometryOccludedFunction(g, occluded);
    rtcCommitGeometry(g);
    return g;
}

} // namespace

LensScene::LensScene(EmbreeDevice& device, const LensAtWavelength& L) {
    const optics::Lens& lens = *L.lens;
    surfaceCount_ = lens.surfaces.size();
    scene_ = rtcNewScene(device.get());
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_NONE);
    device.check("creating the lens scene");

    double largest = 0.0;
    for (double r : L.clipRadius) largest = std::max(largest, r);
    if (largest <= 0.0) largest = 100.0;
    const double unclippedRadius = 1.5 * largest; // bounds for surfaces with no clear aperture given

    unsigned id = 0;
    for (std::size_t s = 0; s < surfaceCount_; ++s, ++id) {
        auto p = std::make_unique<SurfacePrim>();
        p->surface = lens.surfaces[s];
        p->vertexZ = L.vertexZ[s];
        p->radius = L.clipRadius[s];
        p->boundsRadius = p->radius > 0.0 ? p->radius : unclippedRadius;
        p->isStop = (s == L.stop);
        p->iris = L.iris;
        RTCGeometry g = newUserGeometry(device, p.get(), surfaceBounds, intersectN<SurfacePrim, surfaceHitT>,
                                        occludedN<SurfacePrim, surfaceHitT>);
        rtcAttachGeometryByID(scene_, g, id);
        rtcReleaseGeometry(g);
        surfaces_.push_back(std::move(p));
    }

    // The iris plane, where the stop is a flat surface of its own. A stop on a curved surface (the
    // Cooke triplet's rear surface of its flint) is that surface's clear aperture, clipped by the
    // blade polygon at the hit point (SurfacePrim::inside): a plane at its vertex would cut through
    // the glass near the rim and block light that passes.
    if (lens.surfaces[L.stop].isFlat()) {
        iris_ = std::make_unique<IrisPrim>();
        iris_->z = L.vertexZ[L.stop];
        iris_->outerRadius = 2.0 * largest;
        iris_->iris = L.iris;
        RTCGeometry irisGeom = newUserGeometry(device, iris_.get(), irisBounds, intersectN<IrisPrim, irisHitT>,
                                               occludedN<IrisPrim, irisHitT>);
        rtcAttachGeometryByID(scene_, irisGeom, id++);
        rtcReleaseGeometry(irisGeom);
    }

    // Barrel: a tube between the rims of consecutive surfaces with clear apertures.
    for (std::size_t s = 0; s + 1 < surfaceCount_; ++s) {
        const double r0 = L.clipRadius[s], r1 = L.clipRadius[s + 1];
        if (r0 <= 0.0 || r1 <= 0.0) continue;
        // From the lowest point of one rim to the highest of the next (one point each where round).
        const auto rim0 = lens.surfaces[s].rimRange(r0), rim1 = lens.surfaces[s + 1].rimRange(r1);
        if (!rim0 || !rim1) continue;
        auto b = std::make_unique<BarrelPrim>();
        b->radius = std::max(r0, r1) * (1.0 + 1e-9);
        b->z0 = L.vertexZ[s] + rim0->first;
        b->z1 = L.vertexZ[s + 1] + rim1->second;
        if (b->z1 <= b->z0) continue;
        RTCGeometry g = newUserGeometry(device, b.get(), barrelBounds, intersectN<BarrelPrim, barrelHitT>,
                                        occludedN<BarrelPrim, barrelHitT>);
        rtcAttachGeometryByID(scene_, g, id++);
        rtcReleaseGeometry(g);
        barrel_.push_back(std::move(b));
    }
    rtcCommitScene(scene_);
    device.check("building the lens scene");
}

LensScene::~LensScene() {
    if (scene_) rtcReleaseScene(scene_);
}

} // namespace ff::trace
