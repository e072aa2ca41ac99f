#include "ghosts/ghost_table.h"

#include "core/error.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "core/units.h"
#include "ghosts/entry_tracer.h"
#include "ghosts/table_refinement.h"
#include "optics/paraxial.h"
#include "trace/traced_flare.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

namespace ff::ghosts {

std::string TableSettings::key() const {
    std::string k = "table-v23 lambda";
    for (double l : wavelengthsNm) k += " " + text::roundTrip(l);
    k += " sampling " + std::to_string(static_cast<int>(sampling)) + " grid " + std::to_string(grid) + " sensor " +
         std::to_string(static_cast<int>(sensor)) + " coating " + std::to_string(static_cast<int>(coating)) + " max " +
         text::roundTrip(maxAngleDeg) + " tol " + text::roundTrip(interpolationTolerance) + " angles " +
         std::to_string(maxAngles) + " sensorsize " + text::roundTrip(sensorSizeMm.first) + "x" +
         text::roundTrip(sensorSizeMm.second) + " edges " + std::to_string(edgeSubdivisions);
    return k;
}

TableSettings TableSettings::named(int grid, const std::string& sampling, const std::string& sensor,
                                   const std::string& coating, double maxAngleDeg, int maxAngles, double tolerance) {
    auto require = [](bool ok, const std::string& what) {
        if (!ok) throw Error(ErrorKind::Usage, what);
    };
    require(grid >= 4 && grid <= 512,
            "the table's grid (table_grid, --table-grid) must be 4..512 rays per side, got " + std::to_string(grid));
    require(maxAngleDeg >= 0.0 && maxAngleDeg <= 85.0,
            "the table's largest field angle (max_angle, --max-angle) must be 0..85 degrees");
    require(maxAngles >= 9 && maxAngles <= 513,
            "the table's angles per ghost (table_angles, --table-angles) must be 9..513, got " +
                std::to_string(maxAngles));
    require(tolerance >= 1e-6 && tolerance <= 1.0, "the table's tolerance (tolerance, --tolerance) must be 1e-6..1");
    TableSettings s;
    s.grid = grid;
    s.sampling = trace::samplingNamed(sampling);
    s.sensor = trace::sensorPlaneNamed(sensor);
    s.coating = trace::coatingNamed(coating);
    s.maxAngleDeg = maxAngleDeg;
    s.maxAngles = maxAngles;
    s.interpolationTolerance = tolerance;
    return s;
}

namespace {

void requireSymmetric(const optics::Lens& lens) {
    if (!lens.rotationallySymmetric())
        throw Error(ErrorKind::Input, SourceLocation{lens.file},
                    "the lens has anamorphic surfaces; a ghost table needs a rotationally symmetric lens");
}

// Intervals are not split below maxAngle / kFinestDivision (0.0002 deg on a 25 deg field). A ghost
// refines alone, so following one of its kinks deeper costs about two traces per halving, and the
// square-root kinks (a part of a ghost vignetted away) improve by only sqrt(2) per halving
// (docs/sampling-cases.md, "Square-root kinks"). What fails at this floor is then handled there
// (table_refinement.h):
// pieces of light an entry's search lost are carried to it from its neighbour, and kinks get a knot.
constexpr double kFinestDivision = 131072.0;

// Runs one step of the refinement, adding the traces it spent and its time to the report's step.
template <typename F>
auto timed(BuildReport::Step& step, std::size_t& spent, F&& f) {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t before = spent;
    auto result = f();
    step.traces += spent - before;
    step.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace

TableEntry GhostTable::at(std::size_t ghost, std::size_t w, double a) const {
    const TableGhost& g = ghosts[ghost];
    const auto [i, t] = locate(g.anglesDeg, a);
    const auto& row = g.entries[w];
    return g.anglesDeg.size() < 2 ? row[0] : interpolate(row[i], row[i + 1], t);
}

double GhostTable::directAt(std::size_t w, double a) const {
    const auto [i, t] = locate(anglesDeg, a);
    return anglesDeg.size() < 2 ? directY[w][0] : directY[w][i] + (directY[w][i + 1] - directY[w][i]) * t;
}

double GhostTable::magnification(std::size_t ghost, std::size_t w, double a) const {
    // On the axis both heights vanish: use the ghost's first non-zero angle.
    const std::vector<double>& own = ghosts[ghost].anglesDeg;
    const double angle = (own.size() > 1 && a < own[1]) ? std::max(a, own[1]) : a;
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

std::size_t GhostTable::entryCount() const {
    std::size_t n = 0;
    for (const TableGhost& g : ghosts) n += g.anglesDeg.size();
    return n;
}

namespace {

// Every ghost on the same 9 uniform angles, 0..maxAngle, its intervals not yet measured.
std::vector<GhostNodes> traceStart(EntryTracer& tracer, double maxAngle, BuildReport& report, std::size_t& spent) {
    const std::size_t nG = tracer.pairs().size();
    std::vector<GhostNodes> nodes(nG);
    std::vector<Task> tasks;
    for (std::size_t g = 0; g < nG; ++g)
        for (int i = 0; i <= 8; ++i) tasks.push_back({g, maxAngle * i / 8.0, {}});
    Traced traced = timed(report.start, spent, [&] {
        spent += tasks.size();
        return tracer.trace(tasks);
    });
    for (std::size_t k = 0; k < tasks.size(); ++k) {
        GhostNodes& n = nodes[tasks[k].ghost];
        n.angles.push_back(tasks[k].angleDeg);
        n.rows.push_back(std::move(traced.rows[k]));
        n.found.push_back(std::move(traced.found[k]));
    }
    for (GhostNodes& n : nodes) n.intervals.assign(n.angles.size() - 1, Interval{});
    return nodes;
}

// The intervals to measure this round: unmeasured ones wider than the finest step (at the finest step
// too where their ghost was traced again on a finer grid: Interval::remeasure), of any ghost; when the
// budget cannot take them all, the ones with the largest estimate x width go first (the rest keep
// their estimate): a light falls in an interval in proportion to its width, and an interval astride
// a kink (a part of a ghost vignetted away) cannot take the whole budget.
std::vector<Todo> intervalsToMeasure(const std::vector<GhostNodes>& nodes, const RefinementLimits& limits,
                                     std::size_t budget, std::size_t spent) {
    const std::size_t nG = nodes.size();
    std::vector<Todo> todo;
    for (std::size_t g = 0; g < nG; ++g) {
        const GhostNodes& n = nodes[g];
        for (std::size_t i = 0; i < n.intervals.size(); ++i) {
            const double width = n.angles[i + 1] - n.angles[i];
            const Interval& v = n.intervals[i];
            if (!v.measured && (width > limits.minStep || v.remeasure)) todo.push_back({g, i, v.error * width});
        }
    }
    const std::size_t room = budget > spent ? budget - spent : 0;
    if (todo.size() > room) {
        std::stable_sort(todo.begin(), todo.end(),
                         [](const Todo& a, const Todo& b) { return a.priority > b.priority; });
        todo.resize(room);
        std::sort(todo.begin(), todo.end(), [](const Todo& a, const Todo& b) {
            return a.ghost != b.ghost ? a.ghost < b.ghost : a.interval < b.interval;
        });
    }
    return todo;
}

// The mid-angle of each interval to measure; its search looks where its two neighbours' searches
// found light.
std::vector<Task> midAngleTasks(const std::vector<GhostNodes>& nodes, const std::vector<Todo>& todo) {
    std::vector<Task> tasks;
    for (const Todo& d : todo) {
        const GhostNodes& n = nodes[d.ghost];
        trace::PupilHints hints = n.found[d.interval].pieces;
        const trace::PupilHints& other = n.found[d.interval + 1].pieces;
        for (std::size_t w = 0; w < hints.size() && w < other.size(); ++w)
            hints[w].insert(hints[w].end(), other[w].begin(), other[w].end());
        tasks.push_back(
            {d.ghost, 0.5 * (n.angles[d.interval] + n.angles[d.interval + 1]), std::move(hints), false, n.gridScale});
    }
    return tasks;
}

// The strongest ghost's flux at each mid-angle and wavelength: traced where this round traced it,
// interpolated from the ghost's entries elsewhere.
std::map<double, std::vector<double>> strongestAtMids(const std::vector<GhostNodes>& nodes,
                                                      const std::vector<Task>& tasks, const Traced& mids,
                                                      std::size_t nW) {
    std::map<double, std::vector<double>> strongest;
    for (const Task& task : tasks)
        if (!strongest.count(task.angleDeg)) strongest.emplace(task.angleDeg, strongestFlux(nodes, task.angleDeg, nW));
    for (std::size_t k = 0; k < tasks.size(); ++k)
        for (std::size_t w = 0; w < nW; ++w) {
            double& flux = strongest[tasks[k].angleDeg][w];
            flux = std::max(flux, mids.rows[k][w].flux);
        }
    return strongest;
}

// Every mid-angle becomes an entry of its ghost. A passing interval leaves two halves that keep its
// error; a failing one leaves two halves to be measured; one beside an entry traced again (with the
// estimate in `estimates`) is measured again.
void insertMids(std::vector<GhostNodes>& nodes, const std::vector<Todo>& todo, const std::vector<Task>& tasks,
                Traced& mids, const std::vector<std::pair<double, bool>>& errors,
                const std::map<Node, double>& estimates, double tolerance) {
    for (std::size_t k = 0; k < todo.size();) {
        const std::size_t g = todo[k].ghost;
        GhostNodes& n = nodes[g];
        GhostNodes next;
        next.gridScale = n.gridScale;
        for (std::size_t i = 0; i < n.angles.size(); ++i) {
            next.angles.push_back(n.angles[i]);
            next.rows.push_back(std::move(n.rows[i]));
            next.found.push_back(std::move(n.found[i]));
            if (i + 1 == n.angles.size()) break;
            if (k < todo.size() && todo[k].ghost == g && todo[k].interval == i) {
                const auto [e, relevant] = errors[k];
                const Interval half{e <= tolerance, relevant, e};
                next.intervals.push_back(half);
                next.angles.push_back(tasks[k].angleDeg);
                next.rows.push_back(std::move(mids.rows[k]));
                next.found.push_back(std::move(mids.found[k]));
                next.intervals.push_back(half);
                ++k;
            } else {
                Interval kept = n.intervals[i];
                for (const std::size_t e : {i, i + 1})
                    if (const auto it = estimates.find({g, e}); it != estimates.end()) {
                        kept.measured = false;
                        kept.compared = false;
                        kept.error = std::max(kept.error, it->second);
                    }
                next.intervals.push_back(kept);
            }
        }
        n = std::move(next);
    }
}

// The table's interpolation error: over the final intervals of the ghosts that counted there.
void summariseErrors(const std::vector<GhostNodes>& nodes, const EntryTracer& tracer, double tolerance, GhostTable& t) {
    BuildReport& report = t.build;
    const std::size_t nG = nodes.size();
    std::vector<double> errors;
    double field = 0.0, fieldWithin = 0.0;
    for (std::size_t g = 0; g < nG; ++g) {
        const GhostNodes& n = nodes[g];
        for (std::size_t i = 0; i < n.intervals.size(); ++i) {
            if (!n.intervals[i].relevant) continue;
            errors.push_back(n.intervals[i].error);
            if (n.intervals[i].error > report.worst.error)
                report.worst = {tracer.pairs()[g].label(), n.angles[i], n.angles[i + 1], n.intervals[i].error};
            const double width = n.angles[i + 1] - n.angles[i];
            field += width;
            if (n.intervals[i].error <= tolerance) fieldWithin += width;
        }
    }
    t.withinTolerance = field > 0.0 ? fieldWithin / field : 1.0;
    std::sort(errors.begin(), errors.end());
    t.interpolationError = errors.empty() ? 0.0 : errors.back();
    t.interpolationErrorMedian = errors.empty() ? 0.0 : errors[errors.size() / 2];
    t.interpolationErrorP95 =
        errors.empty() ? 0.0
                       : errors[std::min(errors.size() - 1, static_cast<std::size_t>(0.95 * double(errors.size())))];
}

// The entries: the direct image at every angle any ghost uses, and each ghost's rows.
void fillEntries(const EntryTracer& tracer, const std::vector<GhostNodes>& nodes, std::size_t nW, GhostTable& t) {
    const std::size_t nG = nodes.size();
    t.directY.assign(nW, {});
    for (const auto& [angle, d] : tracer.directs()) {
        t.anglesDeg.push_back(angle);
        for (std::size_t w = 0; w < nW; ++w) t.directY[w].push_back(d.y[w]);
    }
    for (std::size_t g = 0; g < nG; ++g) {
        TableGhost tg;
        tg.pair = tracer.pairs()[g];
        tg.anglesDeg = nodes[g].angles;
        tg.entries.assign(nW, std::vector<TableEntry>(tg.anglesDeg.size()));
        for (std::size_t a = 0; a < tg.anglesDeg.size(); ++a)
            for (std::size_t w = 0; w < nW; ++w) tg.entries[w][a] = nodes[g].rows[a][w];
        t.ghosts.push_back(std::move(tg));
    }
}

} // namespace

GhostTable buildGhostTable(const optics::Lens& lensIn, const TableSettings& s, const Progress& progress) {
    requireSymmetric(lensIn);
    const auto start = Clock::now();
    const optics::Lens lens = trace::withCoating(lensIn, s.coating);
    EntryTracer tracer(lens, s, progress);
    GhostTable t;
    t.lensName = lens.name;
    t.lensFile = lens.file;
    t.lensHash = lens.contentHash;
    t.settingsKey = s.key();
    t.efl = optics::paraxialEfl(lens, lines::d);
    t.sensorZ = tracer.sensorZ();
    t.sensorSizeMm = lens.sensorMm.value_or(s.sensorSizeMm);
    t.apertureBlades = lens.apertureBlades;
    t.bladeRotationDeg = lens.bladeRotationDeg;
    t.wavelengthsNm = s.wavelengthsNm;
    const double maxAngle = s.maxAngleDeg > 0.0
                                ? s.maxAngleDeg
                                : trace::sensorCornerFieldDeg(lens, t.sensorZ, lens.sensorMm.value_or(s.sensorSizeMm));
    const std::size_t nW = s.wavelengthsNm.size(), nG = tracer.pairs().size();
    // The budget counts traced entries (traced again too): maxAngles per ghost on average.
    const std::size_t budget = static_cast<std::size_t>(std::max(s.maxAngles, 9)) * nG;
    const RefinementLimits limits{s.interpolationTolerance, maxAngle / kFinestDivision,
                                  0.01 * 0.5 * t.sensorSizeMm.second, budget};

    // Every ghost starts on the same 9 uniform angles; each then refines its own intervals.
    tracer.setTotalWork(budget);
    BuildReport& report = t.build;
    report.budget = budget;
    std::size_t spent = 0;
    std::vector<GhostNodes> nodes = traceStart(tracer, maxAngle, report, spent);
    for (;; ++report.rounds) {
        const std::vector<Todo> todo = intervalsToMeasure(nodes, limits, budget, spent);
        if (todo.empty()) {
            // What still fails is at the finest step (table_refinement.h).
            if (spent < budget &&
                (timed(report.carried, spent, [&] { return carryPieces(tracer, nodes, limits, spent); }) ||
                 timed(report.knots, spent, [&] { return splitAtKinks(tracer, nodes, limits, spent); }) ||
                 timed(report.finer, spent, [&] { return traceFiner(tracer, nodes, limits, spent); })))
                continue;
            break;
        }
        std::vector<Task> tasks = midAngleTasks(nodes, todo);
        Traced mids = timed(report.midAngles, spent, [&] {
            spent += tasks.size();
            return tracer.trace(tasks);
        });
        const std::vector<Node> retraced = timed(
            report.neighbours, spent, [&] { return retraceNeighbours(tracer, nodes, todo, mids, budget, spent); });
        std::map<double, std::vector<double>> strongest = strongestAtMids(nodes, tasks, mids, nW);
        // The measured intervals' errors; an entry traced again passes its largest to the intervals
        // beside it that are not measured this round, as their estimate until they are.
        std::vector<std::pair<double, bool>> errors(todo.size());
        std::map<Node, double> estimates;
        for (const Node& e : retraced) estimates.emplace(e, 0.0);
        for (std::size_t k = 0; k < todo.size(); ++k) {
            const GhostNodes& n = nodes[todo[k].ghost];
            const std::size_t i = todo[k].interval;
            errors[k] =
                midError(n.rows[i], n.rows[i + 1], mids.rows[k], 0.5, strongest[tasks[k].angleDeg], limits.floorMm);
            for (const std::size_t e : {i, i + 1})
                if (const auto it = estimates.find({todo[k].ghost, e}); it != estimates.end())
                    it->second = std::max(it->second, errors[k].first);
        }
        insertMids(nodes, todo, tasks, mids, errors, estimates, s.interpolationTolerance);
    }
    tracer.finish();
    report.budgetSpent = spent >= budget;
    for (const GhostNodes& n : nodes) report.finerGhosts += n.gridScale > 1;
    summariseErrors(nodes, tracer, s.interpolationTolerance, t);
    fillEntries(tracer, nodes, nW, t);
    t.buildSeconds = secondsSince(start);
    return t;
}

std::vector<std::vector<std::vector<TableEntry>>> traceEntries(const optics::Lens& lensIn, const TableSettings& s,
                                                               const std::vector<double>& anglesDeg,
                                                               const std::vector<std::string>& onlyGhosts) {
    requireSymmetric(lensIn);
    const optics::Lens lens = trace::withCoating(lensIn, s.coating);
    const Progress none;
    EntryTracer tracer(lens, s, none);
    std::vector<std::size_t> ghosts;
    for (std::size_t g = 0; g < tracer.pairs().size(); ++g)
        if (onlyGhosts.empty()) ghosts.push_back(g);
    for (const std::string& label : onlyGhosts) {
        const auto& pairs = tracer.pairs();
        const auto it =
            std::find_if(pairs.begin(), pairs.end(), [&](const trace::GhostPair& p) { return p.label() == label; });
        if (it == pairs.end())
            throw Error(ErrorKind::Input, SourceLocation{lens.file}, "the lens has no ghost " + label);
        ghosts.push_back(static_cast<std::size_t>(it - pairs.begin()));
    }
    std::vector<Task> tasks;
    for (double a : anglesDeg)
        for (std::size_t g : ghosts) tasks.push_back({g, a, {}});
    std::vector<std::vector<TableEntry>> rows = tracer.trace(tasks).rows;
    std::vector<std::vector<std::vector<TableEntry>>> out(anglesDeg.size());
    for (std::size_t k = 0; k < tasks.size(); ++k) out[k / ghosts.size()].push_back(std::move(rows[k]));
    return out;
}

} // namespace ff::ghosts
