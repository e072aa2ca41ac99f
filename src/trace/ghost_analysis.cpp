#include "trace/ghost_analysis.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/bundle_moments.h"
#include "trace/embree_tracer.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ff::trace {

namespace {

PathStats statistics(const Bundle& b, const std::vector<RayResult>& results, double halfW, double halfH) {
    const BundleMoments m = measureBundle(b, results);
    PathStats st;
    st.launched = m.launched;
    st.surviving = m.surviving;
    st.blocked = m.blocked;
    st.energy = m.energy;
    if (m.energy <= 0.0) return st;
    st.centroidX = m.centroidX;
    st.centroidY = m.centroidY;
    st.rmsRadius = std::sqrt(m.mxx + m.myy);
    double inside = 0.0;
    for (std::size_t i = 0; i < results.size(); ++i) {
        const RayResult& r = results[i];
        if (b.launched[i] && r.status == optics::RayStatus::Ok && std::abs(r.sensorPoint.x) <= halfW &&
            std::abs(r.sensorPoint.y) <= halfH)
            inside += r.weight * b.cellArea;
    }
    st.onSensor = inside / m.energy;
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
    const LensAtWavelength geometry(lens, lines::d, report.sensorZ, LensAtWavelength::Films::Exact);
    const EmbreeTracer tracer(geometry);

    // Each path's pupil region, found once for all wavelengths (over the regions at the shortest and
    // the longest). Paths are independent and stored by index, so the report does not depend on the
    // number of threads.
    std::vector<LensAtWavelength> ends;
    if (!o.wavelengthsNm.empty()) {
        const auto [shortest, longest] = std::minmax_element(o.wavelengthsNm.begin(), o.wavelengthsNm.end());
        ends = {LensAtWavelength(lens, *shortest, report.sensorZ), LensAtWavelength(lens, *longest, report.sensorZ)};
    }
    std::vector<std::optional<GhostPair>> paths = {std::nullopt};
    for (const GhostPair& g : ghosts) paths.push_back(g);
    std::vector<std::vector<PathStep>> steps(paths.size());
    std::vector<PupilRegion> regions(paths.size());
    tbb::parallel_for(std::size_t(0), paths.size(), [&](std::size_t p) {
        steps[p] = pathSteps(lens, paths[p]);
        regions[p] = bandRegion(frame, o.field, o.sampling, ends, steps[p]);
    });

    for (double lambda : o.wavelengthsNm) {
        const LensAtWavelength L(lens, lambda, report.sensorZ);
        std::vector<PathStats> stats(paths.size());
        tbb::parallel_for(std::size_t(0), paths.size(), [&](std::size_t p) {
            const Bundle b = regionBundle(frame, o.field, regions[p], o.grid);
            std::vector<RayResult> results(b.rays.size());
            tracer.trace(L, steps[p], b.rays, results);
            stats[p] = statistics(b, results, halfW, halfH);
            stats[p].ghost = paths[p];
        });
        WavelengthReport wr;
        wr.lambdaNm = lambda;
        wr.direct = stats[0];
        wr.ghosts.assign(stats.begin() + 1, stats.end());
        const double directEnergy = wr.direct.energy;
        auto finish = [&](PathStats& st) {
            st.relativeEnergy = directEnergy > 0.0 ? st.energy / directEnergy : 0.0;
            st.energyPerRay = st.launched ? st.relativeEnergy / static_cast<double>(st.launched) : 0.0;
            st.axialRatio = std::abs(wr.direct.centroidY) > 1e-9 ? st.centroidY / wr.direct.centroidY
                                                                 : std::numeric_limits<double>::quiet_NaN();
        };
        finish(wr.direct);
        for (PathStats& g : wr.ghosts) finish(g);
        std::stable_sort(wr.ghosts.begin(), wr.ghosts.end(),
                         [](const PathStats& a, const PathStats& b) { return a.energy > b.energy; });
        for (const PathStats& g : wr.ghosts) wr.totalGhostRelative += g.relativeEnergy;
        report.wavelengths.push_back(std::move(wr));
    }
    return report;
}

} // namespace ff::trace
