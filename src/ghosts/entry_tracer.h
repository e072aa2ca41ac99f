#pragma once
// The ghost table's tracer (internal to ghost_table.cpp): one ghost at one field angle into a table
// entry per wavelength, the direct image that normalises it, and the progress of the build. The
// refinement over field angles that decides what to trace is buildGhostTable's.

#include "ghosts/table_data.h"
#include "trace/bundle_moments.h"
#include "trace/embree_tracer.h"
#include "trace/pupil_sampling.h"
#include "trace/pupil_search.h"

#include <atomic>
#include <map>
#include <mutex>
#include <vector>

namespace ff::ghosts {

// The direct image at one field angle: its centroid and its energy (which normalises every ghost's
// flux there), per wavelength.
struct DirectResult {
    std::vector<double> y, energy;
};

// One ghost at one field angle, with where light was found at its neighbouring angles.
struct Task {
    std::size_t ghost = 0;
    double angleDeg = 0.0;
    trace::PupilHints hints;
    bool lookCloser = false; ///< at the hints (trace::searchPupil)
    int gridScale = 1;       ///< the ghost's grids are this many times the table's (GhostNodes::gridScale)
};

// A task's entry, [wavelength], and what its search found.
struct Traced {
    std::vector<std::vector<TableEntry>> rows; ///< [task][wavelength]
    std::vector<trace::PupilSearch> found;     ///< [task]
};

class EntryTracer {
  public:
    EntryTracer(const optics::Lens& lens, const TableSettings& s, const Progress& progress);

    const std::vector<trace::GhostPair>& pairs() const { return pairs_; }
    double sensorZ() const { return sensorZ_; }

    void setTotalWork(std::size_t total) { total_ = total; }
    /// The refinement may stop before its budget: the work is then all done.
    void finish() {
        if (progress_ && done_ > 0) progress_(done_, done_);
    }

    /// The direct image at every angle traced so far.
    const std::map<double, DirectResult>& directs() const { return direct_; }

    /// Direct images at every angle not yet traced.
    void traceDirect(const std::vector<double>& anglesDeg);

    /// Whether looking where the hints say finds light at this ghost and angle that `known`, its
    /// search there, did not (trace::hintsFindLight).
    bool hintsFindLight(std::size_t ghost, double angleDeg, const trace::PupilSearch& known,
                        const trace::PupilHints& hints, bool lookCloser = false) const;

    /// Every task's entry and search (direct images traced first where missing).
    Traced trace(const std::vector<Task>& tasks);

  private:
    /// The grid for a part of a ghost's pupil (see the definition), times scale.
    int gridFor(const trace::PupilRegion& r, int scale = 1) const;
    /// The bundle's moments, its vignetting edges (and the light between its rays that the region
    /// search's litPoints show) resolved on sub-grids (TableSettings::edgeSubdivisions).
    trace::BundleMoments measure(std::size_t w, const std::vector<trace::PathStep>& steps, const trace::Field& field,
                                 const trace::Bundle& b, const std::vector<trace::RayResult>& c,
                                 const std::vector<trace::RayResult>& k, double scale, double maxRadius,
                                 std::span<const glm::dvec2> litPoints) const;
    void report();

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
    std::map<double, DirectResult> direct_;
    std::atomic<std::size_t> done_{0};
    std::size_t total_ = 0;
    std::mutex mutex_;
};

} // namespace ff::ghosts
