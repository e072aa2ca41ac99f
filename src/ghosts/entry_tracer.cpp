#include "ghosts/entry_tracer.h"

#include "core/units.h"
#include "trace/flare_raster.h"
#include "trace/traced_flare.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace ff::ghosts {

namespace {

// One part of a ghost's pupil, traced: its centre and corner rays.
struct PartTrace {
    trace::Bundle centres, corners;
    std::vector<trace::RayResult> c, k;
};

} // namespace

EntryTracer::EntryTracer(const optics::Lens& lens, const TableSettings& s, const Progress& progress)
    : lens_(lens), s_(s), progress_(progress), sensorZ_(trace::sensorPlaneZ(lens, s.sensor)),
      frame_(trace::pupilFrame(lens)), geometry_(lens, lines::d, sensorZ_), tracer_(geometry_) {
    for (const trace::GhostPair& g : trace::enumerateGhosts(lens)) {
        pairs_.push_back(g);
        steps_.push_back(trace::pathSteps(lens, g));
    }
    for (double l : s.wavelengthsNm) atLambda_.emplace_back(lens, l, sensorZ_);
    // Light landing beyond twice the sensor's half-diagonal can never reach the frame.
    const auto size = lens.sensorMm.value_or(s.sensorSizeMm);
    fitOptions_.maxRadiusMm = std::hypot(size.first, size.second);
    directSteps_ = trace::pathSteps(lens, std::nullopt);
}

void EntryTracer::traceDirect(const std::vector<double>& anglesDeg) {
    std::vector<double> todo;
    for (double a : anglesDeg)
        if (!direct_.count(a)) todo.push_back(a);
    std::sort(todo.begin(), todo.end());
    todo.erase(std::unique(todo.begin(), todo.end()), todo.end());
    const std::size_t nW = s_.wavelengthsNm.size();
    std::vector<DirectResult> out(todo.size(), DirectResult{std::vector<double>(nW), std::vector<double>(nW)});
    tbb::parallel_for(std::size_t(0), todo.size(), [&](std::size_t a) {
        const trace::Field field{degToRad(todo[a]), 0.0};
        for (std::size_t w = 0; w < nW; ++w) {
            const trace::PupilRegion region =
                trace::pupilRegion(frame_, field, s_.sampling, atLambda_[w], directSteps_);
            const trace::Bundle b = trace::regionBundle(frame_, field, region, gridFor(region));
            const trace::Bundle corners = trace::cornerBundle(frame_, field, b);
            std::vector<trace::RayResult> hits(b.rays.size()), k(corners.rays.size());
            tracer_.trace(atLambda_[w], directSteps_, b.rays, hits);
            tracer_.trace(atLambda_[w], directSteps_, corners.rays, k);
            const trace::BundleMoments m = measure(w, directSteps_, field, b, hits, k, 1.0, 0.0, region.litPoints);
            out[a].energy[w] = m.energy;
            out[a].y[w] = m.centroidY;
        }
    });
    for (std::size_t a = 0; a < todo.size(); ++a) direct_.emplace(todo[a], std::move(out[a]));
}

bool EntryTracer::hintsFindLight(std::size_t ghost, double angleDeg, const trace::PupilSearch& known,
                                 const trace::PupilHints& hints, bool lookCloser) const {
    const trace::Field field{degToRad(angleDeg), 0.0};
    return trace::hintsFindLight(frame_, field, s_.sampling, atLambda_, steps_[ghost], fitOptions_.maxRadiusMm, known,
                                 hints, lookCloser);
}

Traced EntryTracer::trace(const std::vector<Task>& tasks) {
    std::vector<double> angles;
    for (const Task& t : tasks) angles.push_back(t.angleDeg);
    traceDirect(angles);
    const std::size_t nW = s_.wavelengthsNm.size();
    Traced traced{std::vector<std::vector<TableEntry>>(tasks.size(), std::vector<TableEntry>(nW)),
                  std::vector<trace::PupilSearch>(tasks.size())};
    std::vector<std::vector<TableEntry>>& out = traced.rows;
    tbb::parallel_for(std::size_t(0), tasks.size(), [&](std::size_t task) {
        const std::size_t g = tasks[task].ghost;
        const DirectResult& d = direct_.at(tasks[task].angleDeg);
        const trace::Field field{degToRad(tasks[task].angleDeg), 0.0};
        // Each wavelength's own region: a ghost's lit pupil can change shape with the wavelength,
        // not only shift (docs/sampling-cases.md, "Light that changes with the wavelength"). Where the light falls in
        // pieces far apart, each piece gets a grid at its own scale; the wavelengths' searches tell one another where
        // they found light, and look where the ghost's neighbouring angles found it (trace::searchPupil).
        trace::PupilSearch& found = traced.found[task];
        found = trace::searchPupil(frame_, field, s_.sampling, atLambda_, steps_[g], fitOptions_.maxRadiusMm,
                                   tasks[task].hints, tasks[task].lookCloser);
        for (std::size_t w = 0; w < nW; ++w) {
            if (d.energy[w] <= 0.0) continue;
            const std::vector<trace::PupilRegion>& regions = found.parts[w];
            const double scale = 1.0 / d.energy[w];
            std::vector<PartTrace> parts(regions.size());
            std::vector<trace::BundleMoments> moments;
            std::vector<BundlePart> views;
            for (std::size_t p = 0; p < regions.size(); ++p) {
                PartTrace& t = parts[p];
                t.centres = trace::regionBundle(frame_, field, regions[p], gridFor(regions[p], tasks[task].gridScale));
                t.corners = trace::cornerBundle(frame_, field, t.centres);
                t.c.resize(t.centres.rays.size());
                t.k.resize(t.corners.rays.size());
                tracer_.trace(atLambda_[w], steps_[g], t.centres.rays, t.c);
                tracer_.trace(atLambda_[w], steps_[g], t.corners.rays, t.k);
                moments.push_back(measure(w, steps_[g], field, t.centres, t.c, t.k, scale, fitOptions_.maxRadiusMm,
                                          regions[p].litPoints));
                views.push_back({&t.centres, &t.c, &t.k});
            }
            const trace::BundleMoments m = trace::combineMoments(moments);
            const GhostFit f = fitGhost(views, scale, fitOptions_, &m);
            TableEntry& e = out[task][w];
            e.centroidY = f.centroidY;
            e.sigmaR = f.sigmaR;
            e.sigmaT = f.sigmaT;
            e.flux = f.flux;
            e.surviving = f.survivingFraction;
            e.gaussian = f.gaussian;
            e.cos2 = f.cos2;
        }
        // The search is kept for its pieces (where neighbouring angles look for light); its lit points
        // have served.
        for (std::vector<trace::PupilRegion>& parts : found.parts)
            for (trace::PupilRegion& r : parts) std::vector<glm::dvec2>().swap(r.litPoints);
        report();
    });
    return traced;
}

// The table's grid, refined where it would under-sample the light: doubled (at most twice) while
// less than kMinLit of the region is lit (a ghost nearly vignetted away falls between a handful of
// rays), and 8x where more than kMaxThin of the region search's lit points are one point thick
// (a band or ring of light narrower than that pass's spacing, which a grid as coarse lets slip
// between its rays, and the edge sub-grids with it), 16x where more than kAllThin are (a part
// that is all thin band; docs/sampling-cases.md, "Parts that are all band"). Either way the
// moments would move in steps as the field angle moves the light across the rays.
int EntryTracer::gridFor(const trace::PupilRegion& r, int scale) const {
    constexpr double kMinLit = 0.1, kMaxThin = 0.05, kAllThin = 0.5;
    const int base = scale * s_.grid;
    if (r.thinShare > kAllThin) return 16 * base;
    if (r.thinShare > kMaxThin) return 8 * base;
    int n = base;
    for (double lit = r.litFraction; lit < kMinLit && n < 4 * base; lit *= 4.0) n *= 2;
    return n;
}

trace::BundleMoments EntryTracer::measure(std::size_t w, const std::vector<trace::PathStep>& steps,
                                          const trace::Field& field, const trace::Bundle& b,
                                          const std::vector<trace::RayResult>& c,
                                          const std::vector<trace::RayResult>& k, double scale, double maxRadius,
                                          std::span<const glm::dvec2> litPoints) const {
    if (s_.edgeSubdivisions <= 1) return trace::measureBundle(b, c, scale, maxRadius);
    return trace::measureBundleResolved(tracer_, atLambda_[w], steps, frame_, field, b, c, k, s_.edgeSubdivisions,
                                        scale, maxRadius, litPoints);
}

void EntryTracer::report() {
    const std::size_t d = ++done_;
    if (!progress_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    progress_(std::min(d, total_), std::max(total_, d));
}

} // namespace ff::ghosts
