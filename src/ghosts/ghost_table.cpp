#include "ghosts/ghost_table.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/bundle_moments.h"
#include "trace/flare_raster.h"
#include "trace/traced_flare.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>

namespace ff::ghosts {

std::string TableSettings::key() const {
    std::string k = "table-v2 lambda";
    for (double l : wavelengthsNm) k += " " + text::roundTrip(l);
    k += " sampling " + std::to_string(static_cast<int>(sampling)) + " grid " + std::to_string(grid) + " sensor " +
         std::to_string(static_cast<int>(sensor)) + " coating " + std::to_string(static_cast<int>(coating)) + " max " +
         text::roundTrip(maxAngleDeg) + " tol " + text::roundTrip(interpolationTolerance) + " angles " + std::to_string(maxAngles) +
         " sensorsize " + text::roundTrip(sensorSizeMm.first) + "x" + text::roundTrip(sensorSizeMm.second) + " edges " +
         std::to_string(edgeSubdivisions);
    return k;
}

namespace {

// Linear interpolation weight of angle a between table angles (index, fraction).
std::pair<std::size_t, double> locate(const std::vector<double>& angles, double a) {
    if (angles.size() < 2 || a <= angles.front()) return {0, 0.0};
    if (a >= angles.back()) return {angles.size() - 2, 1.0};
    const auto it = std::upper_bound(angles.begin(), angles.end(), a);
    const std::size_t i = static_cast<std::size_t>(it - angles.begin()) - 1;
    return {i, (a - angles[i]) / (angles[i + 1] - angles[i])};
}

double lerp(double a, double b, double t) { return a + (b - a) * t; }

ProfileFit lerp(const ProfileFit& a, const ProfileFit& b, double t) {
    return {lerp(a.widthR, b.widthR, t), lerp(a.widthT, b.widthT, t), lerp(a.peak, b.peak, t), lerp(a.error, b.error, t)};
}

TableEntry lerp(const TableEntry& a, const TableEntry& b, double t) {
    TableEntry e;
    e.centroidY = lerp(a.centroidY, b.centroidY, t);
    e.sigmaR = lerp(a.sigmaR, b.sigmaR, t);
    e.sigmaT = lerp(a.sigmaT, b.sigmaT, t);
    e.flux = lerp(a.flux, b.flux, t);
    e.surviving = lerp(a.surviving, b.surviving, t);
    e.gaussian = lerp(a.gaussian, b.gaussian, t);
    e.cos2 = lerp(a.cos2, b.cos2, t);
    return e;
}

// Everything traced at one field angle: the direct image per wavelength and every ghost's entry.
struct AngleResult {
    std::vector<double> directY;                 // [wavelength]
    std::vector<std::vector<TableEntry>> ghosts; // [ghost][wavelength]
};

class Builder {
public:
    Builder(const optics::Lens& lens, const TableSettings& s, const Progress& progress)
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

    const std::vector<trace::GhostPair>& pairs() const { return pairs_; }
    double sensorZ() const { return sensorZ_; }

    void setTotalWork(std::size_t total) { total_ = total; }

    std::vector<AngleResult> trace(const std::vector<double>& anglesDeg) {
        std::vector<AngleResult> out(anglesDeg.size());
        const std::size_t nW = s_.wavelengthsNm.size(), nG = pairs_.size();
        // Direct images first: they normalise every ghost's flux.
        std::vector<std::vector<double>> directEnergy(anglesDeg.size(), std::vector<double>(nW, 0.0));
        tbb::parallel_for(std::size_t(0), anglesDeg.size(), [&](std::size_t a) {
            const trace::Field field{degToRad(anglesDeg[a]), 0.0};
            const trace::PupilRegion region = trace::pupilRegion(frame_, field, s_.sampling, geometry_, directSteps_);
            const trace::Bundle b = trace::regionBundle(frame_, field, region, s_.grid);
            const trace::Bundle corners = trace::cornerBundle(frame_, field, b);
            out[a].directY.assign(nW, 0.0);
            out[a].ghosts.assign(nG, std::vector<TableEntry>(nW));
            for (std::size_t w = 0; w < nW; ++w) {
                std::vector<trace::RayResult> hits(b.rays.size()), k(corners.rays.size());
                tracer_.trace(atLambda_[w], directSteps_, b.rays, hits);
                tracer_.trace(atLambda_[w], directSteps_, corners.rays, k);
                const trace::BundleMoments m = measure(w, directSteps_, field, b, hits, k, 1.0, 0.0);
                directEnergy[a][w] = m.energy;
                out[a].directY[w] = m.centroidY;
            }
        });
        tbb::parallel_for(std::size_t(0), anglesDeg.size() * nG, [&](std::size_t task) {
            const std::size_t a = task / nG, g = task % nG;
            const trace::Field field{degToRad(anglesDeg[a]), 0.0};
            const trace::PupilRegion region = trace::pupilRegion(frame_, field, s_.sampling, geometry_, steps_[g]);
            const trace::Bundle centres = trace::regionBundle(frame_, field, region, s_.grid);
            const trace::Bundle corners = trace::cornerBundle(frame_, field, centres);
            for (std::size_t w = 0; w < nW; ++w) {
                if (directEnergy[a][w] <= 0.0) continue;
                std::vector<trace::RayResult> c(centres.rays.size()), k(corners.rays.size());
                tracer_.trace(atLambda_[w], steps_[g], centres.rays, c);
                tracer_.trace(atLambda_[w], steps_[g], corners.rays, k);
                const double scale = 1.0 / directEnergy[a][w];
                const trace::BundleMoments m = measure(w, steps_[g], field, centres, c, k, scale, fitOptions_.maxRadiusMm);
                const GhostFit f = fitGhost(centres, c, k, scale, fitOptions_, &m);
                TableEntry& e = out[a].ghosts[g][w];
                e.centroidY = f.centroidY;
                e.sigmaR = f.sigmaR;
                e.sigmaT = f.sigmaT;
                e.flux = f.flux;
                e.surviving = f.survivingFraction;
                e.gaussian = f.gaussian;
                e.cos2 = f.cos2;
            }
            report();
        });
        return out;
    }

private:
    // The bundle's moments, its vignetting edges resolved on sub-grids (TableSettings::edgeSubdivisions).
    trace::BundleMoments measure(std::size_t w, const std::vector<trace::PathStep>& steps, const trace::Field& field, const trace::Bundle& b,
                                 const std::vector<trace::RayResult>& c, const std::vector<trace::RayResult>& k, double scale,
                                 double maxRadius) const {
        if (s_.edgeSubdivisions <= 1) return trace::measureBundle(b, c, scale, maxRadius);
        return trace::measureBundleResolved(tracer_, atLambda_[w], steps, frame_, field, b, c, k, s_.edgeSubdivisions, scale, maxRadius);
    }

    void report() {
        const std::size_t d = ++done_;
        if (!progress_) return;
        std::lock_guard<std::mutex> lock(mutex_);
        progress_(d, std::max(total_, d));
    }

    const optics::Lens& lens_;
    const TableSettings& s_;
    const Progress& progress_;
    double sensorZ_;
    trace::PupilFrame frame_;
    trace::LensAtWavelength geometry_;
    trace::EmbreeTracer tracer_;
    std::vector<trace::LensAtWavelength> atLambda_;
    std::vector<trace::GhostPair> pairs_;
    std::vector<std::vector<trace::PathStep>> steps_;
    std::vector<trace::PathStep> directSteps_;
    FitOptions fitOptions_;
    std::atomic<std::size_t> done_{0};
    std::size_t total_ = 0;
    std::mutex mutex_;
};

// Relative interpolation error at one mid-angle (see the header): the largest over the ghosts that
// carry at least 1 % of the strongest ghost's flux there, over all wavelengths. floorMm keeps the
// centroid's scale from vanishing for tightly focused ghosts near the axis.
double midError(const AngleResult& lo, const AngleResult& hi, const AngleResult& mid, std::size_t nW, double floorMm) {
    double worst = 0.0;
    for (std::size_t w = 0; w < nW; ++w) {
        double strongest = 0.0;
        for (const auto& g : mid.ghosts) strongest = std::max(strongest, g[w].flux);
        for (std::size_t g = 0; g < mid.ghosts.size(); ++g) {
            const TableEntry& t = mid.ghosts[g][w];
            if (t.flux < 0.01 * strongest || t.sigmaR <= 0.0 || lo.ghosts[g][w].flux <= 0.0 || hi.ghosts[g][w].flux <= 0.0) continue;
            const TableEntry i = lerp(lo.ghosts[g][w], hi.ghosts[g][w], 0.5);
            worst = std::max(worst, std::abs(i.centroidY - t.centroidY) / std::max({std::abs(t.centroidY), t.sigmaR, floorMm}));
            worst = std::max(worst, std::abs(i.sigmaR - t.sigmaR) / t.sigmaR);
            if (t.sigmaT > 0.0) worst = std::max(worst, std::abs(i.sigmaT - t.sigmaT) / t.sigmaT);
        }
    }
    return worst;
}

void requireSymmetric(const optics::Lens& lens) {
    if (!lens.rotationallySymmetric())
        throw Error(ErrorKind::Input, SourceLocation{lens.file}, "the lens has anamorphic surfaces; a ghost table needs a rotationally symmetric lens");
}

// Intervals are not split below maxAngle / kFinestDivision. What still fails there is a kink (part of
// a ghost vignetted away, its spread changing like a square root of the angle), which halving
// improves by only sqrt(2) each time, or the entries' sampling noise: neither is worth the budget.
constexpr double kFinestDivision = 512.0;

double defaultMaxAngle(const optics::Lens& lens, const TableSettings& s, double sensorZ) {
    const auto size = lens.sensorMm.value_or(s.sensorSizeMm);
    const double halfDiagonal = 0.5 * std::hypot(size.first, size.second) * 1.05;
    try {
        return radToDeg(trace::fieldForSensorPoint(lens, sensorZ, 0.0, halfDiagonal).angleRad);
    } catch (const Error&) {
        // The chief ray cannot reach the corner: fall back to the paraxial field.
        return std::min(80.0, radToDeg(std::atan(halfDiagonal / std::abs(optics::paraxialEfl(lens, lines::d)))));
    }
}

} // namespace

TableEntry GhostTable::at(std::size_t ghost, std::size_t w, double a) const {
    const auto [i, t] = locate(anglesDeg, a);
    const auto& row = ghosts[ghost].entries[w];
    return anglesDeg.size() < 2 ? row[0] : lerp(row[i], row[i + 1], t);
}

double GhostTable::directAt(std::size_t w, double a) const {
    const auto [i, t] = locate(anglesDeg, a);
    return anglesDeg.size() < 2 ? directY[w][0] : lerp(directY[w][i], directY[w][i + 1], t);
}

double GhostTable::magnification(std::size_t ghost, std::size_t w, double a) const {
    // On the axis both heights vanish: use the first non-zero angle.
    const double angle = (anglesDeg.size() > 1 && a < anglesDeg[1]) ? std::max(a, anglesDeg[1]) : a;
    const double d = directAt(w, angle);
    return d != 0.0 ? at(ghost, w, angle).centroidY / d : 0.0;
}

std::size_t GhostTable::nearestWavelength(double lambda) const {
    std::size_t best = 0;
    for (std::size_t w = 1; w < wavelengthsNm.size(); ++w)
        if (std::abs(wavelengthsNm[w] - lambda) < std::abs(wavelengthsNm[best] - lambda)) best = w;
    return best;
}

std::array<std::size_t, 3> GhostTable::rgbChannels() const {
    return {nearestWavelength(650.0), nearestWavelength(550.0), nearestWavelength(450.0)};
}

GhostTable buildGhostTable(const optics::Lens& lensIn, const TableSettings& s, const Progress& progress) {
    requireSymmetric(lensIn);
    const auto start = std::chrono::steady_clock::now();
    const optics::Lens lens = trace::withCoating(lensIn, s.coating);
    Builder builder(lens, s, progress);
    GhostTable t;
    t.lensName = lens.name;
    t.lensFile = lens.file;
    t.lensHash = lens.contentHash;
    t.settingsKey = s.key();
    t.efl = optics::paraxialEfl(lens, lines::d);
    t.sensorZ = builder.sensorZ();
    t.sensorSizeMm = lens.sensorMm.value_or(s.sensorSizeMm);
    t.apertureBlades = lens.apertureBlades;
    t.bladeRotationDeg = lens.bladeRotationDeg;
    t.wavelengthsNm = s.wavelengthsNm;
    const double maxAngle = s.maxAngleDeg > 0.0 ? s.maxAngleDeg : defaultMaxAngle(lens, s, t.sensorZ);
    const std::size_t nW = s.wavelengthsNm.size(), nG = builder.pairs().size();

    // Nodes: angles with their traced rows. Each interval between neighbours is either measured
    // (the error of interpolating at its mid-angle) or waiting to be measured, with its parent's
    // measured error kept as the estimate should the angle budget run out first.
    struct Interval {
        bool measured = false;
        double error = 0.0; ///< measured error, or the parent's while not measured
    };
    std::vector<double> angles;
    for (int i = 0; i <= 8; ++i) angles.push_back(maxAngle * i / 8.0);
    const double minStep = maxAngle / kFinestDivision;
    builder.setTotalWork(nG * static_cast<std::size_t>(std::max(s.maxAngles, 9)));
    std::vector<AngleResult> rows = builder.trace(angles);
    std::vector<Interval> intervals(angles.size() - 1);
    for (;;) {
        // Unmeasured intervals wider than the finest step; when the budget cannot take them all, the
        // ones with the largest estimate x width go first (the rest keep their estimate): a light
        // falls in an interval in proportion to its width, and an interval astride a kink (a part of
        // a ghost vignetted away) cannot take the whole budget.
        std::vector<std::size_t> todo;
        for (std::size_t i = 0; i < intervals.size(); ++i)
            if (!intervals[i].measured && angles[i + 1] - angles[i] > minStep) todo.push_back(i);
        const std::size_t budget = static_cast<std::size_t>(std::max(s.maxAngles, 0));
        const std::size_t room = angles.size() < budget ? budget - angles.size() : 0;
        if (todo.size() > room) {
            std::stable_sort(todo.begin(), todo.end(), [&](std::size_t a, std::size_t b) {
                return intervals[a].error * (angles[a + 1] - angles[a]) > intervals[b].error * (angles[b + 1] - angles[b]);
            });
            todo.resize(room);
            std::sort(todo.begin(), todo.end());
        }
        if (todo.empty()) break;
        std::vector<double> mids;
        for (std::size_t i : todo) mids.push_back(0.5 * (angles[i] + angles[i + 1]));
        std::vector<AngleResult> midRows = builder.trace(mids);
        // Every mid-angle becomes a node. A passing interval leaves two halves that keep its error; a
        // failing one leaves two halves to be measured.
        std::vector<double> newAngles;
        std::vector<AngleResult> newRows;
        std::vector<Interval> newIntervals;
        std::size_t next = 0;
        for (std::size_t i = 0; i < angles.size(); ++i) {
            newAngles.push_back(angles[i]);
            newRows.push_back(std::move(rows[i]));
            if (i + 1 == angles.size()) break;
            if (next < todo.size() && todo[next] == i) {
                const double e = midError(newRows.back(), rows[i + 1], midRows[next], nW, 0.01 * 0.5 * t.sensorSizeMm.second);
                const Interval half{e <= s.interpolationTolerance, e};
                newIntervals.push_back(half);
                newAngles.push_back(mids[next]);
                newRows.push_back(std::move(midRows[next]));
                newIntervals.push_back(half);
                ++next;
            } else {
                newIntervals.push_back(intervals[i]);
            }
        }
        angles = std::move(newAngles);
        rows = std::move(newRows);
        intervals = std::move(newIntervals);
        if (angles.size() >= static_cast<std::size_t>(s.maxAngles)) break;
    }
    std::vector<double> errors;
    for (const Interval& i : intervals) errors.push_back(i.error);
    std::sort(errors.begin(), errors.end());
    t.interpolationError = errors.empty() ? 0.0 : errors.back();
    t.interpolationErrorMedian = errors.empty() ? 0.0 : errors[errors.size() / 2];
    t.interpolationErrorP95 = errors.empty() ? 0.0 : errors[std::min(errors.size() - 1, static_cast<std::size_t>(0.95 * double(errors.size())))];

    t.anglesDeg = angles;
    t.directY.assign(nW, std::vector<double>(angles.size()));
    for (std::size_t a = 0; a < angles.size(); ++a)
        for (std::size_t w = 0; w < nW; ++w) t.directY[w][a] = rows[a].directY[w];
    for (std::size_t g = 0; g < nG; ++g) {
        TableGhost tg;
        tg.pair = builder.pairs()[g];
        tg.entries.assign(nW, std::vector<TableEntry>(angles.size()));
        for (std::size_t a = 0; a < angles.size(); ++a)
            for (std::size_t w = 0; w < nW; ++w) tg.entries[w][a] = rows[a].ghosts[g][w];
        t.ghosts.push_back(std::move(tg));
    }
    t.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return t;
}

std::vector<std::vector<std::vector<TableEntry>>> traceEntries(const optics::Lens& lensIn, const TableSettings& s,
                                                               const std::vector<double>& anglesDeg) {
    requireSymmetric(lensIn);
    const optics::Lens lens = trace::withCoating(lensIn, s.coating);
    const Progress none;
    Builder builder(lens, s, none);
    std::vector<std::vector<std::vector<TableEntry>>> out;
    for (AngleResult& r : builder.trace(anglesDeg)) out.push_back(std::move(r.ghosts));
    return out;
}

} // namespace ff::ghosts
