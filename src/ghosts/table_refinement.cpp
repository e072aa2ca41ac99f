#include "ghosts/table_refinement.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace ff::ghosts {

std::pair<std::size_t, double> locate(const std::vector<double>& angles, double a) {
    if (angles.size() < 2 || a <= angles.front()) return {0, 0.0};
    if (a >= angles.back()) return {angles.size() - 2, 1.0};
    const auto it = std::upper_bound(angles.begin(), angles.end(), a);
    const std::size_t i = static_cast<std::size_t>(it - angles.begin()) - 1;
    return {i, (a - angles[i]) / (angles[i + 1] - angles[i])};
}

namespace {

double lerp(double a, double b, double t) {
    return a + (b - a) * t;
}

ProfileFit lerp(const ProfileFit& a, const ProfileFit& b, double t) {
    return {lerp(a.widthR, b.widthR, t), lerp(a.widthT, b.widthT, t), lerp(a.peak, b.peak, t),
            lerp(a.error, b.error, t)};
}

void append(trace::PupilHints& to, const trace::PupilHints& more) {
    to.resize(std::max(to.size(), more.size()));
    for (std::size_t w = 0; w < more.size(); ++w) to[w].insert(to[w].end(), more[w].begin(), more[w].end());
}

bool empty(const trace::PupilHints& h) {
    return std::all_of(h.begin(), h.end(), [](const auto& boxes) { return boxes.empty(); });
}

// The error of the interval an entry at the finest step was the mid-angle of, measured again from
// the entries as they are now: the entry interpolated from its two neighbours, where they lie at
// equal distances on either side of it, as its parent interval's ends did.
std::optional<std::pair<double, bool>> parentError(const std::vector<GhostNodes>& nodes, std::size_t g, std::size_t j,
                                                   double floorMm) {
    const GhostNodes& n = nodes[g];
    if (j == 0 || j + 1 >= n.angles.size()) return std::nullopt;
    const double left = n.angles[j] - n.angles[j - 1], right = n.angles[j + 1] - n.angles[j];
    if (std::abs(left - right) > 1e-6 * (left + right)) return std::nullopt;
    const std::vector<double> strongest = strongestFlux(nodes, n.angles[j], n.rows[j].size());
    return midError(n.rows[j - 1], n.rows[j + 1], n.rows[j], 0.5, strongest, floorMm);
}

// Whether interval i of a ghost fails at the finest step: it counts, errs over the tolerance and
// is too narrow to bisect.
bool failsAtFinestStep(const GhostNodes& n, std::size_t i, const RefinementLimits& limits) {
    const Interval& v = n.intervals[i];
    return v.relevant && v.error > limits.tolerance && n.width(i) <= limits.minStep;
}

} // namespace

// Carries pieces of light between the two entries of every failing interval at the finest step not
// yet compared: each entry is traced again where the other's pieces, far from its own, are found
// there. The intervals beside an entry traced again wait to be measured again; at the finest step
// their error is estimated again at once from the entries as they are now (parentError).
bool carryPieces(EntryTracer& tracer, std::vector<GhostNodes>& nodes, const RefinementLimits& limits,
                 std::size_t& spent) {
    std::map<Node, trace::PupilHints> hints;
    for (std::size_t g = 0; g < nodes.size(); ++g) {
        GhostNodes& n = nodes[g];
        for (std::size_t i = 0; i < n.intervals.size(); ++i) {
            Interval& v = n.intervals[i];
            if (v.compared || v.carried >= kMaxCarried || !failsAtFinestStep(n, i, limits)) continue;
            v.compared = true;
            for (const auto& [e, other] : {std::pair{i, i + 1}, std::pair{i + 1, i}}) {
                const trace::PupilHints away = trace::piecesAwayFrom(n.found[other], n.found[e]);
                if (!empty(away)) append(hints[{g, e}], away);
            }
        }
    }
    const std::vector<Node> retraced = retraceWithHints(tracer, nodes, hints, true, limits.budget, spent);
    for (const auto& [g, j] : retraced) {
        GhostNodes& n = nodes[g];
        for (const std::size_t i : {j - 1, j}) {
            if (i >= n.intervals.size()) continue; // j - 1 wraps for the first entry
            Interval& v = n.intervals[i];
            v.measured = false;
            v.compared = false;
            if (n.width(i) > limits.minStep) continue;
            ++v.carried;
            std::optional<std::pair<double, bool>> estimate;
            for (const std::size_t e : {i, i + 1})
                if (const auto p = parentError(nodes, g, e, limits.floorMm);
                    p && (!estimate || p->first > estimate->first))
                    estimate = p;
            if (estimate) std::tie(v.error, v.relevant) = *estimate;
        }
    }
    return !retraced.empty();
}

// Splits every failing interval at the finest step, not split so before, at its kink (kinkAngle),
// and measures both parts at their mid-angles: three entries each, while the budget lasts. Across
// a kink linear interpolation errs by a share that only halves with each bisection (a piece of light
// whose flux falls linearly to zero far from the rest: its share of the second moment kinks); a
// knot on it leaves two smooth parts.
bool splitAtKinks(EntryTracer& tracer, std::vector<GhostNodes>& nodes, const RefinementLimits& limits,
                  std::size_t& spent) {
    struct Knot {
        std::size_t ghost, interval;
        double error, angle;
    };
    std::vector<Knot> knots;
    for (std::size_t g = 0; g < nodes.size(); ++g) {
        const GhostNodes& n = nodes[g];
        for (std::size_t i = 0; i < n.intervals.size(); ++i) {
            const Interval& v = n.intervals[i];
            if (!v.knotted && failsAtFinestStep(n, i, limits)) knots.push_back({g, i, v.error, 0.0});
        }
    }
    const std::size_t room = limits.budget > spent ? (limits.budget - spent) / 3 : 0;
    if (knots.size() > room) {
        std::stable_sort(knots.begin(), knots.end(), [](const Knot& a, const Knot& b) { return a.error > b.error; });
        knots.resize(room);
    }
    if (knots.empty()) return false;
    std::sort(knots.begin(), knots.end(), [](const Knot& a, const Knot& b) {
        return a.ghost != b.ghost ? a.ghost < b.ghost : a.interval < b.interval;
    });

    const std::size_t nW = nodes[knots.front().ghost].rows.front().size();
    std::vector<Task> tasks;
    for (Knot& k : knots) {
        const GhostNodes& n = nodes[k.ghost];
        const double lo = n.angles[k.interval], hi = n.angles[k.interval + 1];
        k.angle = kinkAngle(n, k.interval, strongestFlux(nodes, 0.5 * (lo + hi), nW), limits.floorMm);
        trace::PupilHints hints = n.found[k.interval].pieces;
        append(hints, n.found[k.interval + 1].pieces);
        for (const double a : {0.5 * (lo + k.angle), k.angle, 0.5 * (k.angle + hi)})
            tasks.push_back({k.ghost, a, hints, true, n.gridScale});
    }
    Traced traced = tracer.trace(tasks);
    spent += tasks.size();

    // Each knot's two parts, measured at their mid-angles; then the three entries join their ghost.
    std::vector<std::pair<double, bool>> errors(2 * knots.size());
    for (std::size_t k = 0; k < knots.size(); ++k) {
        const GhostNodes& n = nodes[knots[k].ghost];
        const auto& lo = n.rows[knots[k].interval];
        const auto& hi = n.rows[knots[k].interval + 1];
        const auto& knot = traced.rows[3 * k + 1];
        for (const std::size_t side : {0, 1}) {
            const std::size_t m = 3 * k + 2 * side;
            std::vector<double> strongest = strongestFlux(nodes, tasks[m].angleDeg, nW);
            for (std::size_t w = 0; w < nW; ++w) strongest[w] = std::max(strongest[w], traced.rows[m][w].flux);
            errors[2 * k + side] =
                midError(side == 0 ? lo : knot, side == 0 ? knot : hi, traced.rows[m], 0.5, strongest, limits.floorMm);
        }
    }
    for (std::size_t k = knots.size(); k-- > 0;) {
        GhostNodes& n = nodes[knots[k].ghost];
        const auto i = static_cast<std::ptrdiff_t>(knots[k].interval);
        std::vector<Interval> parts;
        for (const std::size_t side : {0, 1}) {
            const auto [e, relevant] = errors[2 * k + side];
            const Interval part{e <= limits.tolerance, relevant, e, false, true};
            parts.insert(parts.end(), {part, part});
        }
        n.intervals.erase(n.intervals.begin() + i);
        n.intervals.insert(n.intervals.begin() + i, parts.begin(), parts.end());
        for (std::size_t j = 3; j-- > 0;) {
            n.angles.insert(n.angles.begin() + i + 1, tasks[3 * k + j].angleDeg);
            n.rows.insert(n.rows.begin() + i + 1, std::move(traced.rows[3 * k + j]));
            n.found.insert(n.found.begin() + i + 1, std::move(traced.found[3 * k + j]));
        }
    }
    return true;
}

// Traces every entry of each ghost with a failing interval at the finest step again on grids twice
// as fine, worst ghost first. Such an interval may join two entries each measured too coarsely, in
// error alike over stretches of angle (which the interpolation error cannot see) and stepping where
// the light crosses the rays (docs/sampling-cases.md, "Entries measured too coarsely"). Each entry
// is told where it found light before; every interval of the ghost is measured again, from entries
// on one grid.
bool traceFiner(EntryTracer& tracer, std::vector<GhostNodes>& nodes, const RefinementLimits& limits,
                std::size_t& spent) {
    std::vector<std::pair<double, std::size_t>> failing; // (worst error, ghost)
    for (std::size_t g = 0; g < nodes.size(); ++g) {
        const GhostNodes& n = nodes[g];
        if (n.gridScale >= kMaxGridScale) continue;
        double worst = 0.0;
        for (std::size_t i = 0; i < n.intervals.size(); ++i)
            if (failsAtFinestStep(n, i, limits)) worst = std::max(worst, n.intervals[i].error);
        if (worst > 0.0) failing.push_back({worst, g});
    }
    std::stable_sort(failing.begin(), failing.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<Task> tasks;
    std::vector<std::size_t> chosen;
    for (const auto& [error, g] : failing) {
        const GhostNodes& n = nodes[g];
        if (spent + tasks.size() + n.angles.size() > limits.budget) continue;
        chosen.push_back(g);
        for (std::size_t j = 0; j < n.angles.size(); ++j)
            tasks.push_back({g, n.angles[j], n.found[j].pieces, true, 2 * n.gridScale});
    }
    if (tasks.empty()) return false;
    Traced traced = tracer.trace(tasks);
    spent += tasks.size();
    std::size_t k = 0;
    for (const std::size_t g : chosen) {
        GhostNodes& n = nodes[g];
        n.gridScale *= 2;
        for (std::size_t j = 0; j < n.angles.size(); ++j, ++k) {
            n.rows[j] = std::move(traced.rows[k]);
            n.found[j] = std::move(traced.found[k]);
        }
        for (Interval& v : n.intervals) {
            Interval again;
            again.relevant = v.relevant;
            again.error = v.error; // the estimate until measured again
            again.knotted = v.knotted;
            again.remeasure = true;
            v = again;
        }
    }
    return true;
}

TableEntry interpolate(const TableEntry& a, const TableEntry& b, double t) {
    // Where the ghost is dark at one end of the interval (it is switched on or off within it), its
    // shape is the lit end's and only its light fades: interpolating its centroid and widths towards
    // those of no light would shrink it onto the axis.
    if ((a.flux <= 0.0) != (b.flux <= 0.0)) {
        const bool fromB = a.flux <= 0.0;
        TableEntry e = fromB ? b : a;
        const double fade = fromB ? t : 1.0 - t;
        e.flux *= fade;
        e.gaussian.peak *= fade;
        e.cos2.peak *= fade;
        e.surviving = lerp(a.surviving, b.surviving, t);
        return e;
    }
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

double GhostNodes::fluxAt(std::size_t w, double a) const {
    const auto [i, t] = locate(angles, a);
    return angles.size() < 2 ? rows[0][w].flux : lerp(rows[i][w].flux, rows[i + 1][w].flux, t);
}

std::vector<double> strongestFlux(const std::vector<GhostNodes>& nodes, double angleDeg, std::size_t nW) {
    std::vector<double> flux(nW, 0.0);
    for (const GhostNodes& n : nodes)
        if (!n.angles.empty())
            for (std::size_t w = 0; w < nW; ++w) flux[w] = std::max(flux[w], n.fluxAt(w, angleDeg));
    return flux;
}

std::pair<double, bool> midError(const std::vector<TableEntry>& lo, const std::vector<TableEntry>& hi,
                                 const std::vector<TableEntry>& mid, double t, const std::vector<double>& strongest,
                                 double floorMm) {
    double worst = 0.0;
    bool relevant = false;
    for (std::size_t w = 0; w < mid.size(); ++w) {
        const TableEntry& e = mid[w];
        if (e.flux < 0.01 * strongest[w] || e.sigmaR <= 0.0) continue;
        relevant = true;
        const TableEntry i = interpolate(lo[w], hi[w], t);
        worst =
            std::max(worst, std::abs(i.centroidY - e.centroidY) / std::max({std::abs(e.centroidY), e.sigmaR, floorMm}));
        worst = std::max(worst, std::abs(i.sigmaR - e.sigmaR) / e.sigmaR);
        if (e.sigmaT > 0.0) worst = std::max(worst, std::abs(i.sigmaT - e.sigmaT) / e.sigmaT);
    }
    return {worst, relevant};
}

double kinkAngle(const GhostNodes& n, std::size_t i, const std::vector<double>& strongest, double floorMm) {
    const double mid = 0.5 * (n.angles[i] + n.angles[i + 1]);
    if (i == 0 || i + 2 >= n.angles.size()) return mid;
    const double a0 = n.angles[i - 1], a1 = n.angles[i], a2 = n.angles[i + 1], a3 = n.angles[i + 2];
    double worst = 1e-9, at = mid; // relative disagreements below this are no kink
    const auto consider = [&](double q0, double q1, double q2, double q3, double scale) {
        if (!(scale > 0.0)) return;
        const double sL = (q1 - q0) / (a1 - a0), sR = (q3 - q2) / (a3 - a2);
        const double disagreement = std::abs(q1 + sL * (mid - a1) - q2 - sR * (mid - a2)) / scale;
        if (disagreement <= worst) return;
        worst = disagreement;
        at = mid;
        if (sL == sR) return;
        const double x = (q2 - sR * a2 - q1 + sL * a1) / (sL - sR);
        const double margin = 0.05 * (a2 - a1);
        if (x > a1 + margin && x < a2 - margin) at = x;
    };
    for (std::size_t w = 0; w < strongest.size(); ++w) {
        const TableEntry &e0 = n.rows[i - 1][w], &e1 = n.rows[i][w], &e2 = n.rows[i + 1][w], &e3 = n.rows[i + 2][w];
        if (std::min({e0.flux, e1.flux, e2.flux, e3.flux}) <= 0.0 ||
            interpolate(e1, e2, 0.5).flux < 0.01 * strongest[w])
            continue;
        const double sigmaR = 0.5 * (e1.sigmaR + e2.sigmaR), sigmaT = 0.5 * (e1.sigmaT + e2.sigmaT);
        consider(e0.centroidY, e1.centroidY, e2.centroidY, e3.centroidY,
                 std::max({0.5 * std::abs(e1.centroidY + e2.centroidY), sigmaR, floorMm}));
        // The second moments, not the widths, are linear in a piece's flux.
        const auto sq = [](double x) { return x * x; };
        consider(sq(e0.sigmaR), sq(e1.sigmaR), sq(e2.sigmaR), sq(e3.sigmaR), 2.0 * sq(sigmaR));
        consider(sq(e0.sigmaT), sq(e1.sigmaT), sq(e2.sigmaT), sq(e3.sigmaT), 2.0 * sq(sigmaT));
    }
    return at;
}

std::vector<Node> retraceWithHints(EntryTracer& tracer, std::vector<GhostNodes>& nodes,
                                   const std::map<Node, trace::PupilHints>& hints, bool lookCloser, std::size_t budget,
                                   std::size_t& spent) {
    const std::vector<std::pair<Node, trace::PupilHints>> candidates(hints.begin(), hints.end());
    std::vector<char> finds(candidates.size(), 0);
    tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t c) {
        const auto& [node, h] = candidates[c];
        const GhostNodes& n = nodes[node.first];
        finds[c] = tracer.hintsFindLight(node.first, n.angles[node.second], n.found[node.second], h, lookCloser);
    });
    std::vector<Task> again;
    std::vector<Node> which;
    for (std::size_t c = 0; c < candidates.size() && spent + again.size() < budget; ++c) {
        if (!finds[c]) continue;
        // The pieces its search found before go with the new hints: an entry given a piece by one
        // neighbour could otherwise lose one its other neighbour gave it: the zoom's build carried
        // pieces at the finest step six traces a round with 18 500 traces of its budget left (hours);
        // told these, it carried 4 in all.
        const auto& [node, h] = candidates[c];
        trace::PupilHints all = h;
        append(all, nodes[node.first].found[node.second].pieces);
        again.push_back({node.first, nodes[node.first].angles[node.second], std::move(all), lookCloser,
                         nodes[node.first].gridScale});
        which.push_back(node);
    }
    if (again.empty()) return which;
    Traced traced = tracer.trace(again);
    spent += again.size();
    for (std::size_t j = 0; j < again.size(); ++j) {
        GhostNodes& n = nodes[which[j].first];
        n.rows[which[j].second] = std::move(traced.rows[j]);
        n.found[which[j].second] = std::move(traced.found[j]);
    }
    return which;
}

std::vector<Node> retraceNeighbours(EntryTracer& tracer, std::vector<GhostNodes>& nodes, const std::vector<Todo>& todo,
                                    const Traced& mids, std::size_t budget, std::size_t& spent) {
    std::map<Node, trace::PupilHints> hints;
    for (std::size_t k = 0; k < todo.size(); ++k)
        for (const std::size_t e : {todo[k].interval, todo[k].interval + 1}) {
            const trace::PupilHints away = trace::piecesAwayFrom(mids.found[k], nodes[todo[k].ghost].found[e]);
            if (!empty(away)) append(hints[{todo[k].ghost, e}], away);
        }
    return retraceWithHints(tracer, nodes, hints, false, budget, spent);
}

} // namespace ff::ghosts
