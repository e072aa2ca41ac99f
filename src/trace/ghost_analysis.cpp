#include "trace/ghost_analysis.h"

#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/embree_tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ff::trace {

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

namespace {

PathStats statistics(const Bundle& b, const std::vector<RayResult>& results, double halfW, double halfH) {
    PathStats st;
    double e = 0.0, sx = 0.0, sy = 0.0, inside = 0.0;
    for (std::size_t i = 0; i < results.size(); ++i) {
        if (!b.launched[i]) continue;
        ++st.launched;
        const RayResult& r = results[i];
        if (r.status == optics::RayStatus::Blocked) ++st.blocked;
        if (r.status != optics::RayStatus::Ok) continue;
        ++st.surviving;
        const double w = r.weight * b.cellArea;
        e += w;
        sx += w * r.sensorPoint.x;
        sy += w * r.sensorPoint.y;
        if (std::abs(r.sensorPoint.x) <= halfW && std::abs(r.sensorPoint.y) <= halfH) inside += w;
    }
    st.energy = e;
    if (e > 0.0) {
        st.centroidX = sx / e;
        st.centroidY = sy / e;
        double m2 = 0.0;
        for (std::size_t i = 0; i < results.size(); ++i) {
            const RayResult& r = results[i];
            if (!b.launched[i] || r.status != optics::RayStatus::Ok) continue;
            const double dx = r.sensorPoint.x - st.centroidX, dy = r.sensorPoint.y - st.centroidY;
            m2 += r.weight * b.cellArea * (dx * dx + dy * dy);
        }
        st.rmsRadius = std::sqrt(m2 / e);
        st.onSensor = inside / e;
    }
    return st;
}

} // namespace

GhostReport analyzeGhosts(const optics::Lens& lensIn, const GhostAnalysisOptions& o) {
    const optics::Lens lens = withCoating(lensIn, o.coating);
    GhostReport report;
    report.sensorSizeMm = lens.sensorMm.value_or(o.sensorSizeMm);
    report.sensorZ = sensorPlaneZ(lens, o.sensor);
    report.reflectingInterfaces = lens.reflectingInterfaces(lines::d).size();
    const double halfW = 0.5 * report.sensorSizeMm.first, halfH = 0.5 * report.sensorSizeMm.second;
    const PupilFrame frame = pupilFrame(lens);
    const auto ghosts = enumerateGhosts(lens);

    // The scene depends on geometry only; build it once.
    const LensAtWavelength geometry(lens, lines::d, report.sensorZ);
    const EmbreeTracer tracer(geometry);

    for (double lambda : o.wavelengthsNm) {
        const LensAtWavelength L(lens, lambda, report.sensorZ);
        WavelengthReport wr;
        wr.lambdaNm = lambda;
        auto tracePath = [&](const std::optional<GhostPair>& g) {
            const auto steps = pathSteps(lens, g);
            const Bundle b = makeBundle(frame, o.field, o.sampling, o.grid, L, steps);
            std::vector<RayResult> results(b.rays.size());
            tracer.trace(L, steps, b.rays, results);
            PathStats st = statistics(b, results, halfW, halfH);
            st.ghost = g;
            return st;
        };
        wr.direct = tracePath(std::nullopt);
        const double directEnergy = wr.direct.energy;
        for (const GhostPair& g : ghosts) wr.ghosts.push_back(tracePath(g));
        for (PathStats* st : [&] {
                 std::vector<PathStats*> all = {&wr.direct};
                 for (auto& g : wr.ghosts) all.push_back(&g);
                 return all;
             }()) {
            st->relativeEnergy = directEnergy > 0.0 ? st->energy / directEnergy : 0.0;
            st->energyPerRay = st->launched ? st->relativeEnergy / static_cast<double>(st->launched) : 0.0;
            st->axialRatio = std::abs(wr.direct.centroidY) > 1e-9 ? st->centroidY / wr.direct.centroidY
                                                                   : std::numeric_limits<double>::quiet_NaN();
        }
        std::stable_sort(wr.ghosts.begin(), wr.ghosts.end(), [](const PathStats& a, const PathStats& b) { return a.energy > b.energy; });
        for (const PathStats& g : wr.ghosts) wr.totalGhostRelative += g.relativeEnergy;
        report.wavelengths.push_back(std::move(wr));
    }
    return report;
}

} // namespace ff::trace
