#pragma once
// The ghost table's refinement over field angles (internal to ghost_table.cpp): each ghost's entries
// and the intervals between them while the table is built, the error of interpolating across an
// interval, carrying pieces of light between neighbouring entries, and what is done where an
// interval reaches the finest step still failing. The rounds of bisection are buildGhostTable's.

#include "ghosts/entry_tracer.h"
#include "ghosts/table_data.h"

#include <map>
#include <utility>
#include <vector>

namespace ff::ghosts {

/// Linear interpolation weight of angle a between sorted angles: (index, fraction), clamped.
std::pair<std::size_t, double> locate(const std::vector<double>& angles, double a);

/// Linear interpolation of an entry (GhostTable::at: a ghost dark at one end keeps the lit end's shape).
TableEntry interpolate(const TableEntry& a, const TableEntry& b, double t);

/// An interval between two entries of a ghost. It is either measured (the error of interpolating at
/// its mid-angle) or waiting to be, with its parent's error kept as the estimate should the budget
/// run out first (or, at the finest step, for good).
struct Interval {
    bool measured = false;
    bool relevant = false;  ///< the ghost carried >= 1 % of the strongest ghost's flux at the mid-angle
    double error = 0.0;     ///< measured error, or the parent's while not measured
    bool compared = false;  ///< at the finest step: its two entries' pieces of light have been compared
    bool knotted = false;   ///< a part of an interval split at its kink (never split there again)
    int carried = 0;        ///< times an entry of it was traced again at the finest step (at most kMaxCarried)
    bool remeasure = false; ///< measured even at the finest step (its entries were traced on a finer grid)
};

/// An interval at the finest step is compared at most this many times after one of its entries was
/// traced again there: a piece is carried along the entries as far as it lasts, but two entries that
/// kept handing pieces back and forth would spend the whole budget, a few traces a round.
constexpr int kMaxCarried = 8;

/// A ghost's angles while the table is refined: its traced entries and the intervals between them.
struct GhostNodes {
    std::vector<double> angles;
    std::vector<std::vector<TableEntry>> rows; ///< [angle][wavelength]
    std::vector<trace::PupilSearch> found;     ///< [angle]: where its search found light
    std::vector<Interval> intervals;
    int gridScale = 1; ///< its entries' grids are this many times the table's (traceFiner)

    double fluxAt(std::size_t w, double a) const;
    double width(std::size_t interval) const { return angles[interval + 1] - angles[interval]; }
};

/// An interval of a ghost to measure, by its priority.
struct Todo {
    std::size_t ghost, interval;
    double priority;
};

/// An entry of a ghost: (ghost, index of its angle).
using Node = std::pair<std::size_t, std::size_t>;

/// What the refinement is held to.
struct RefinementLimits {
    double tolerance = 0.005;
    double minStep = 0.0; ///< intervals this narrow are not bisected
    double floorMm = 0.0; ///< the smallest scale of a centroid's error
    std::size_t budget = 0;
};

/// The strongest ghost's flux at an angle per wavelength, interpolated from every ghost's entries.
std::vector<double> strongestFlux(const std::vector<GhostNodes>& nodes, double angleDeg, std::size_t nW);

/// Relative error of interpolating one ghost at fraction t of an interval (see the header), the worst
/// over the wavelengths at which it carries at least 1 % of the strongest ghost's flux there. floorMm
/// keeps the centroid's scale from vanishing for tightly focused ghosts near the axis. Returns the
/// error and whether any wavelength counted.
std::pair<double, bool> midError(const std::vector<TableEntry>& lo, const std::vector<TableEntry>& hi,
                                 const std::vector<TableEntry>& mid, double t, const std::vector<double>& strongest,
                                 double floorMm);

/// Where interval i's entries kink (a piece of light vanishing, a part of the pupil vignetted away):
/// the lines through the two entries on either side of it, for the quantity and wavelength on which
/// they disagree most at the mid-angle, meet at the kink; for the spreads, their squares, which are
/// linear in a piece's flux. The mid-angle where they do not meet inside the interval (5 % of it
/// from either end), or where the entries beside it are missing or dark.
double kinkAngle(const GhostNodes& n, std::size_t i, const std::vector<double>& strongest, double floorMm);

/// Traces again, told where to look, the entries whose hints find light their search did not
/// (EntryTracer::hintsFindLight, the looks alone), while the budget lasts. An entry traced again is
/// told where it found light before, too, so that it keeps what earlier hints gave it. Returns those
/// entries.
std::vector<Node> retraceWithHints(EntryTracer& tracer, std::vector<GhostNodes>& nodes,
                                   const std::map<Node, trace::PupilHints>& hints, bool lookCloser, std::size_t budget,
                                   std::size_t& spent);

/// Light a mid-angle's search found far from everything a neighbouring entry's search found was
/// stepped over there, or is not there: the neighbour is traced again where its hints find it
/// (retraceWithHints). Returns the entries traced again.
std::vector<Node> retraceNeighbours(EntryTracer& tracer, std::vector<GhostNodes>& nodes, const std::vector<Todo>& todo,
                                    const Traced& mids, std::size_t budget, std::size_t& spent);

// At the finest step. What fails once no interval wider than the finest step waits fails for one of
// three reasons that bisecting further would fix slowly or never: a piece of light one entry's search
// found and its neighbour's lost (that neighbour's entry is wrong, not the interpolation), a kink
// inside the interval, or entries measured too coarsely (their grid's error, which moves in steps as
// the field angle moves the light across the rays). Pieces are carried first (carryPieces); only
// where none is carried are kinks split (splitAtKinks); only where no kink is left to split are
// ghosts traced on a finer grid (traceFiner). Each returns whether it traced anything.

/// Carries pieces of light between the two entries of every failing interval at the finest step not
/// yet compared: each entry is traced again where the other's pieces, far from its own, are found
/// there. Intervals wider than the finest step beside an entry traced again are left to be measured
/// again; those at the finest step have their error estimated again from the entries as they are now.
bool carryPieces(EntryTracer& tracer, std::vector<GhostNodes>& nodes, const RefinementLimits& limits,
                 std::size_t& spent);

/// Splits every failing interval at the finest step, not split so before, at its kink (kinkAngle)
/// and measures both parts at their mid-angles: three entries each, while the budget lasts.
bool splitAtKinks(EntryTracer& tracer, std::vector<GhostNodes>& nodes, const RefinementLimits& limits,
                  std::size_t& spent);

/// A ghost's grid is doubled at most this many times.
constexpr int kMaxGridScale = 2;

/// Traces again, on grids twice as fine, every entry of each ghost with a failing interval at the
/// finest step (worst first, while the budget lasts; each ghost at most up to kMaxGridScale), and
/// leaves all its intervals to be measured again, those at the finest step too (Interval::remeasure):
/// errors measured on the coarser entries no longer hold.
bool traceFiner(EntryTracer& tracer, std::vector<GhostNodes>& nodes, const RefinementLimits& limits,
                std::size_t& spent);

} // namespace ff::ghosts
