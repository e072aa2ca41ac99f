#include "trace/adaptive_grid.h"

#include "core/error.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace ff::trace {

namespace {

using Vec2 = glm::dvec2;

double cross(const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Whether the triangles (c[i], c[i+1], m) all have one orientation, none degenerate: the cell's
// footprint is star-shaped around its centre and the map does not fold inside it.
bool fanConsistent(const std::array<Vec2, 4>& c, const Vec2& m) {
    int positive = 0, negative = 0;
    for (int i = 0; i < 4; ++i) {
        const double a = cross(m, c[i], c[(i + 1) % 4]);
        positive += a > 0.0;
        negative += a < 0.0;
    }
    return positive == 4 || negative == 4;
}

// Convex hull of up to five points (Andrew's monotone chain), counter-clockwise, without collinear
// points.
std::vector<Vec2> convexHull(std::vector<Vec2> p) {
    std::sort(p.begin(), p.end(), [](const Vec2& a, const Vec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    p.erase(std::unique(p.begin(), p.end()), p.end());
    if (p.size() < 3) return p;
    std::vector<Vec2> h(2 * p.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0.0) --k;
        h[k++] = p[i];
    }
    for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0.0) --k;
        h[k++] = p[i];
    }
    h.resize(k - 1);
    return h;
}

} // namespace

RefineSettings RefineSettings::refined(double R) {
    if (!(R >= 1.0) || !std::isfinite(R)) throw Error(ErrorKind::Usage, "the refinement factor must be >= 1");
    RefineSettings s;
    s.stopPx /= R;
    s.foldStopPx /= R;
    s.edgeStopPx /= R;
    s.linearRel /= R;
    s.weightRel /= R;
    s.maxDepth += static_cast<int>(std::lround(std::log2(R)));
    s.rayBudget = static_cast<std::size_t>(static_cast<double>(s.rayBudget) * R * R);
    return s;
}

RefineSettings RefineSettings::energyOnly() {
    RefineSettings s;
    s.fatesOnly = true;
    s.maxDepth = 4;
    return s;
}

AdaptiveGrid::AdaptiveGrid(int n, double x0, double y0, double cellMm, const std::vector<char>& launched,
                           const RefineSettings& settings, PupilSampler sampler, std::span<const glm::dvec2> litHints)
    : n_(n), x0_(x0), y0_(y0), cellMm_(cellMm), S_(0), settings_(settings), sampler_(std::move(sampler)) {
    if (n < 1 || settings.maxDepth < 0 || settings.maxDepth > 20 ||
        (static_cast<std::uint64_t>(n) << (settings.maxDepth + 2)) >= (1ull << 31))
        throw Error(ErrorKind::Usage, "adaptive grid: " + std::to_string(n) + " cells per side and " +
                                          std::to_string(settings.maxDepth) +
                                          " levels of refinement exceed its lattice");
    S_ = 1u << (settings.maxDepth + 2);
    // Bucket the hints by starting cell (counting sort).
    hintStart_.assign(static_cast<std::size_t>(n) * n + 1, 0);
    std::vector<std::pair<std::size_t, glm::dvec2>> inside;
    for (const glm::dvec2& p : litHints) {
        const glm::dvec2 q = (p - glm::dvec2(x0, y0)) / cellMm;
        if (!(q.x >= 0.0 && q.y >= 0.0 && q.x < n && q.y < n)) continue;
        inside.emplace_back(static_cast<std::size_t>(q.y) * n + static_cast<std::size_t>(q.x), q * double(S_));
        ++hintStart_[inside.back().first + 1];
    }
    for (std::size_t k = 1; k < hintStart_.size(); ++k) hintStart_[k] += hintStart_[k - 1];
    hints_.resize(inside.size());
    std::vector<std::uint32_t> fill(hintStart_.begin(), hintStart_.end() - 1);
    for (const auto& [k, q] : inside) hints_[fill[k]++] = q;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) sampleAt(i * S_, j * S_);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            if (!launched.empty() && !launched[static_cast<std::size_t>(j) * n + i]) continue;
            Cell c;
            c.X = i * S_;
            c.Y = j * S_;
            c.size = S_;
            c.s[0] = sampleAt(c.X, c.Y);
            c.s[1] = sampleAt(c.X + S_, c.Y);
            c.s[2] = sampleAt(c.X + S_, c.Y + S_);
            c.s[3] = sampleAt(c.X, c.Y + S_);
            c.s[4] = sampleAt(c.X + S_ / 2, c.Y + S_ / 2);
            cells_.push_back(c);
        }
    traceQueued();
    // A cell where under two samples arrive has no footprint of its own: it takes the median extent
    // of the starting cells that have one.
    std::vector<double> extents;
    for (Cell& c : cells_) {
        c.energy = ownEnergy(c);
        c.extentPx = footprintExtent(c);
        if (c.extentPx >= 0.0) extents.push_back(c.extentPx);
    }
    double typical = 0.0;
    if (!extents.empty()) {
        std::nth_element(extents.begin(), extents.begin() + static_cast<long>(extents.size() / 2), extents.end());
        typical = extents[extents.size() / 2];
    }
    for (Cell& c : cells_)
        if (c.extentPx < 0.0) c.extentPx = typical;
}

namespace {

constexpr std::uint64_t kEmpty = ~std::uint64_t(0);

std::size_t slotOf(std::uint64_t key, std::size_t mask) {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 20) & mask; // Fibonacci hashing
}

} // namespace

std::uint32_t AdaptiveGrid::sampleAt(std::uint32_t X, std::uint32_t Y) {
    if (2 * (indexed_ + 1) > index_.size()) {
        std::vector<std::pair<std::uint64_t, std::uint32_t>> old(std::max<std::size_t>(1024, 2 * index_.size()),
                                                                 {kEmpty, 0});
        old.swap(index_);
        const std::size_t mask = index_.size() - 1;
        for (const auto& e : old)
            if (e.first != kEmpty) {
                std::size_t i = slotOf(e.first, mask);
                while (index_[i].first != kEmpty) i = (i + 1) & mask;
                index_[i] = e;
            }
    }
    const std::uint64_t key = (static_cast<std::uint64_t>(X) << 32) | Y;
    const std::size_t mask = index_.size() - 1;
    std::size_t i = slotOf(key, mask);
    for (; index_[i].first != kEmpty; i = (i + 1) & mask)
        if (index_[i].first == key) return index_[i].second;
    index_[i] = {key, static_cast<std::uint32_t>(samples_.size())};
    ++indexed_;
    samples_.emplace_back();
    queued_.push_back({x0_ + cellMm_ * X / S_, y0_ + cellMm_ * Y / S_});
    return index_[i].second;
}

void AdaptiveGrid::traceQueued() {
    if (queued_.empty()) return;
    sampler_(queued_, std::span<PupilSample>(samples_).subspan(queuedFrom_, queued_.size()));
    stats_.samples += queued_.size();
    queuedFrom_ = samples_.size();
    queued_.clear();
}

double AdaptiveGrid::ownEnergy(const Cell& c) const {
    auto w = [&](int k) { return samples_[c.s[k]].ok ? samples_[c.s[k]].weight : 0.0; };
    const double side = cellMm_ * c.size / S_;
    return side * side * (0.5 * w(4) + 0.125 * (w(0) + w(1) + w(2) + w(3)));
}

// Whether the box over the cell's arriving samples, grown by the cell's extent on every side, misses
// the frame: none of its light can land in the image, so refining it changes nothing drawn.
bool AdaptiveGrid::offFrame(const Cell& c) const {
    if (frameW_ <= 0) return false;
    Vec2 lo, hi;
    if (footprintBox(c, lo, hi) == 0) return false; // nothing arrived: no footprint to judge
    const double g = c.extentPx;
    return hi.x + g < 0.0 || hi.y + g < 0.0 || lo.x - g > frameW_ || lo.y - g > frameH_;
}

int AdaptiveGrid::footprintBox(const Cell& c, Vec2& lo, Vec2& hi) const {
    lo = Vec2(1e300);
    hi = Vec2(-1e300);
    int arrived = 0;
    for (std::uint32_t k : c.s)
        if (samples_[k].ok) {
            const Vec2& p = samples_[k].px;
            lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
            hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
            ++arrived;
        }
    return arrived;
}

// Largest side of the box over the arriving samples (pixels); -1 where under two arrive.
double AdaptiveGrid::footprintExtent(const Cell& c) const {
    Vec2 lo, hi;
    return footprintBox(c, lo, hi) < 2 ? -1.0 : std::max(hi.x - lo.x, hi.y - lo.y);
}

// Whether the corners' fates change exactly twice around the cell: one edge crosses it.
bool AdaptiveGrid::crossedOnce(const Cell& c) const {
    int changes = 0;
    for (int i = 0; i < 4; ++i) changes += samples_[c.s[i]].ok != samples_[c.s[(i + 1) % 4]].ok;
    return changes == 2;
}

bool AdaptiveGrid::holdsHint(const Cell& c) const {
    const std::size_t k = static_cast<std::size_t>(c.Y / S_) * n_ + c.X / S_;
    for (std::uint32_t h = hintStart_[k]; h < hintStart_[k + 1]; ++h)
        if (hints_[h].x >= c.X && hints_[h].y >= c.Y && hints_[h].x < c.X + c.size && hints_[h].y < c.Y + c.size)
            return true;
    return false;
}

bool AdaptiveGrid::wantsSplit(const Cell& c) const {
    if (c.level >= settings_.maxDepth) return false;
    int arrived = 0;
    for (std::uint32_t k : c.s) arrived += samples_[k].ok;
    if (arrived == 0) return (settings_.fatesOnly || (c.extentPx > settings_.stopPx && !offFrame(c))) && holdsHint(c);
    const bool mixed = arrived < 5;
    if (settings_.fatesOnly) return mixed;
    if (c.extentPx <= settings_.foldStopPx || offFrame(c)) return false;
    const std::array<Vec2, 4> k = {samples_[c.s[0]].px, samples_[c.s[1]].px, samples_[c.s[2]].px, samples_[c.s[3]].px};
    const Vec2 m = samples_[c.s[4]].px;
    if (!mixed && !fanConsistent(k, m)) return true;
    if (c.extentPx <= settings_.stopPx) return false;
    if (mixed) return c.extentPx > settings_.edgeStopPx || !crossedOnce(c);
    const double d = glm::length(m - 0.25 * (k[0] + k[1] + k[2] + k[3]));
    if (d > settings_.linearRel * c.extentPx) return true;
    const double wm = samples_[c.s[4]].weight;
    const double wc =
        0.25 * (samples_[c.s[0]].weight + samples_[c.s[1]].weight + samples_[c.s[2]].weight + samples_[c.s[3]].weight);
    return std::abs(wm - wc) > settings_.weightRel * wm;
}

void AdaptiveGrid::split(std::size_t ci) {
    const Cell parent = cells_[ci];
    const std::uint32_t h = parent.size / 2, q = parent.size / 4, X = parent.X, Y = parent.Y;
    cells_[ci].firstChild = static_cast<std::int32_t>(cells_.size());
    // The 3 x 3 child corners (the parent's corners and centre among them, already traced).
    std::uint32_t g[3][3];
    for (std::uint32_t b = 0; b < 3; ++b)
        for (std::uint32_t a = 0; a < 3; ++a) g[b][a] = sampleAt(X + a * h, Y + b * h);
    for (std::uint32_t b = 0; b < 2; ++b)
        for (std::uint32_t a = 0; a < 2; ++a) {
            Cell c;
            c.X = X + a * h;
            c.Y = Y + b * h;
            c.size = h;
            c.level = parent.level + 1;
            c.s[0] = g[b][a];
            c.s[1] = g[b][a + 1];
            c.s[2] = g[b + 1][a + 1];
            c.s[3] = g[b + 1][a];
            c.s[4] = sampleAt(c.X + q, c.Y + q);
            cells_.push_back(c);
        }
}

void AdaptiveGrid::refine(int frameWidth, int frameHeight) {
    frameW_ = frameWidth;
    frameH_ = frameHeight;
    std::vector<std::size_t> frontier;
    for (std::size_t i = 0; i < cells_.size(); ++i)
        if (cells_[i].firstChild < 0 && wantsSplit(cells_[i])) frontier.push_back(i);
    for (;;) {
        splitLevels(std::move(frontier));
        if (settings_.fatesOnly) break;
        frontier = cutEdges(); // the cuts a cell's centre contradicts are split instead
        if (frontier.empty() || stats_.budgetHit) break;
    }
}

void AdaptiveGrid::splitLevels(std::vector<std::size_t> frontier) {
    while (!frontier.empty()) {
        // At most 8 new samples a split (4 edge midpoints, 4 child centres): past the budget, the
        // cells with the largest footprints go first.
        const std::size_t left = settings_.rayBudget > stats_.samples ? settings_.rayBudget - stats_.samples : 0;
        if (8 * frontier.size() > left) {
            stats_.budgetHit = true;
            std::stable_sort(frontier.begin(), frontier.end(),
                             [&](std::size_t a, std::size_t b) { return cells_[a].extentPx > cells_[b].extentPx; });
            frontier.resize(left / 8);
            std::sort(frontier.begin(), frontier.end());
            if (frontier.empty()) break;
        }
        for (std::size_t ci : frontier) split(ci);
        traceQueued();
        std::vector<std::size_t> next;
        for (std::size_t ci : frontier) {
            const Cell& parent = cells_[ci];
            const auto first = static_cast<std::size_t>(parent.firstChild);
            bool lit = true;
            for (std::uint32_t k : parent.s) lit = lit && samples_[k].ok;
            double own[4], sum = 0.0;
            for (std::size_t c = 0; c < 4; ++c) sum += own[c] = ownEnergy(cells_[first + c]);
            const double share = lit && sum > 0.0 ? parent.energy / sum : 1.0;
            for (std::size_t c = 0; c < 4; ++c) {
                Cell& child = cells_[first + c];
                child.energy = own[c] * share;
                child.extentPx = footprintExtent(child);
                if (child.extentPx < 0.0) child.extentPx = 0.5 * parent.extentPx;
                stats_.depth = std::max(stats_.depth, child.level);
                if (wantsSplit(child)) next.push_back(first + c);
            }
        }
        frontier.swap(next);
    }
}

glm::dvec2 AdaptiveGrid::crossingPx(const Crossing& x) const {
    const Vec2& a = samples_[x.aSample].px;
    // Lattice distances along the side (one of the two coordinates is constant on it).
    const double walked = std::abs(double(x.aX) - x.cornerX) + std::abs(double(x.aY) - x.cornerY);
    const double halfStep = 0.5 * (std::abs(double(x.bX) - x.aX) + std::abs(double(x.bY) - x.aY));
    if (walked <= 0.0) return a;
    return a + (a - samples_[x.cornerSample].px) * (halfStep / walked);
}

// Leaves crossed by one vignetting edge, larger than stopPx: the edge is found on each crossed side
// by bisection to an eighth of stopPx, and the leaf becomes the lit polygon (its arriving corners and the
// two crossings), its energy that polygon's pupil area x the mean weight of its arriving samples.
std::vector<std::size_t> AdaptiveGrid::cutEdges() {
    const std::size_t firstCut = cuts_.size();
    for (std::size_t ci = 0; ci < cells_.size(); ++ci) {
        Cell& c = cells_[ci];
        if (c.firstChild >= 0 || c.cut >= 0 || c.extentPx <= 0.25 * settings_.stopPx || !crossedOnce(c) || offFrame(c))
            continue;
        int arrived = 0;
        for (std::uint32_t k : c.s) arrived += samples_[k].ok;
        if (arrived == 5) continue;
        int rounds = 0;
        while (c.extentPx / std::ldexp(1.0, rounds) > 0.125 * settings_.stopPx && (c.size >> (rounds + 1)) > 0)
            ++rounds;
        Cut cut;
        cut.cell = ci;
        const std::uint32_t X[4] = {c.X, c.X + c.size, c.X + c.size, c.X},
                            Y[4] = {c.Y, c.Y, c.Y + c.size, c.Y + c.size};
        int n = 0;
        for (int i = 0; i < 4; ++i) {
            const int j = (i + 1) % 4;
            if (samples_[c.s[i]].ok == samples_[c.s[j]].ok) continue;
            const int a = samples_[c.s[i]].ok ? i : j, b = a == i ? j : i;
            cut.x[n++] = {i, X[a], Y[a], X[b], Y[b], c.s[a], X[a], Y[a], c.s[a], rounds};
        }
        c.cut = static_cast<std::int32_t>(cuts_.size());
        cuts_.push_back(cut);
    }
    for (bool more = cuts_.size() > firstCut; more;) {
        std::vector<std::pair<Crossing*, std::uint32_t>> pending;
        for (Cut& cut : cuts_)
            for (Crossing& x : cut.x)
                if (x.rounds > 0) pending.emplace_back(&x, sampleAt((x.aX + x.bX) / 2, (x.aY + x.bY) / 2));
        traceQueued();
        more = false;
        for (auto& [x, k] : pending) {
            const std::uint32_t mX = (x->aX + x->bX) / 2, mY = (x->aY + x->bY) / 2;
            if (samples_[k].ok)
                x->aX = mX, x->aY = mY, x->aSample = k;
            else
                x->bX = mX, x->bY = mY;
            --x->rounds;
            more = more || x->rounds > 0;
        }
    }
    std::vector<std::size_t> contradicted;
    for (std::size_t k = firstCut; k < cuts_.size(); ++k) {
        const Cut& cut = cuts_[k];
        Cell& c = cells_[cut.cell];
        const double X[4] = {0.0, 1.0, 1.0, 0.0}, Y[4] = {0.0, 0.0, 1.0, 1.0}; // corners in cell units
        std::vector<Vec2> poly;
        double w = 0.0;
        int count = 0;
        for (int i = 0; i < 4; ++i) {
            if (samples_[c.s[i]].ok) poly.emplace_back(X[i], Y[i]), w += samples_[c.s[i]].weight, ++count;
            for (const Crossing& x : cut.x)
                if (x.side == i) {
                    poly.emplace_back((0.5 * (x.aX + x.bX) - c.X) / c.size, (0.5 * (x.aY + x.bY) - c.Y) / c.size);
                    w += samples_[x.aSample].weight, ++count;
                }
        }
        // The centre must lie on the lit side of the cut exactly when its ray arrives; where it does
        // not (a corner of the light, or a second edge, inside the cell), the cell is split instead.
        const auto crossing = [&](const Crossing& x) {
            return Vec2((0.5 * (x.aX + x.bX) - c.X) / c.size, (0.5 * (x.aY + x.bY) - c.Y) / c.size);
        };
        const Vec2 p1 = crossing(cut.x[0]), p2 = crossing(cut.x[1]);
        const int litCorner = samples_[c.s[0]].ok ? 0 : samples_[c.s[1]].ok ? 1 : samples_[c.s[2]].ok ? 2 : 3;
        const double sideLit = cross(p1, p2, Vec2(X[litCorner], Y[litCorner])),
                     sideCentre = cross(p1, p2, Vec2(0.5, 0.5));
        if (sideCentre != 0.0 && (sideCentre * sideLit > 0.0) != samples_[c.s[4]].ok && c.level < settings_.maxDepth) {
            c.cut = -1;
            contradicted.push_back(cut.cell);
            continue;
        }
        if (samples_[c.s[4]].ok) w += samples_[c.s[4]].weight, ++count;
        double area = 0.0;
        for (std::size_t i = 0; i < poly.size(); ++i) area += cross(Vec2(0.0), poly[i], poly[(i + 1) % poly.size()]);
        const double side = cellMm_ * c.size / S_;
        c.energy = 0.5 * std::abs(area) * side * side * w / count;
    }
    return contradicted;
}

double AdaptiveGrid::energy() const {
    double e = 0.0;
    for (const Cell& c : cells_)
        if (c.firstChild < 0) e += c.energy;
    return e;
}

void AdaptiveGrid::draw(double scale, CoverageRaster& raster, RasterStats& stats) const {
    std::vector<Vec2> poly;
    for (const Cell& c : cells_) {
        if (c.firstChild >= 0 || c.energy <= 0.0) continue;
        const double e = c.energy * scale;
        poly.clear();
        bool all = true;
        for (std::uint32_t k : c.s) all = all && samples_[k].ok;
        const std::array<Vec2, 4> k = {samples_[c.s[0]].px, samples_[c.s[1]].px, samples_[c.s[2]].px,
                                       samples_[c.s[3]].px};
        const Vec2 m = samples_[c.s[4]].px;
        if (all) {
            // A footprint inside one pixel puts all of its energy there.
            const double px = std::floor(m.x), py = std::floor(m.y);
            bool inside = std::abs(px) < 1e9 && std::abs(py) < 1e9;
            for (int i = 0; i < 4 && inside; ++i) inside = std::floor(k[i].x) == px && std::floor(k[i].y) == py;
            if (inside) {
                raster.pixel(static_cast<int>(px), static_cast<int>(py), e, stats);
                continue;
            }
        }
        if (all && fanConsistent(k, m)) {
            // The map taken as affine on each pupil triangle (k_i, k_i+1, centre), a quarter of the
            // cell: each carries the energy of its quarter (by its three weights), so the density
            // follows the map's Jacobian from triangle to triangle.
            double w[4], sum = 0.0;
            for (int i = 0; i < 4; ++i)
                sum += w[i] = samples_[c.s[i]].weight + samples_[c.s[(i + 1) % 4]].weight + samples_[c.s[4]].weight;
            for (int i = 0; i < 4; ++i) {
                const std::array<Vec2, 3> tri = {m, k[i], k[(i + 1) % 4]};
                raster.polygon(tri, sum > 0.0 ? e * w[i] / sum : 0.25 * e, stats);
            }
            continue;
        }
        if (c.cut >= 0) {
            // The lit polygon: the arriving corners and, on the crossed sides, the last arriving
            // point of the bisection.
            const Cut& cut = cuts_[static_cast<std::size_t>(c.cut)];
            for (int i = 0; i < 4; ++i) {
                if (samples_[c.s[i]].ok) poly.push_back(samples_[c.s[i]].px);
                for (const Crossing& x : cut.x)
                    if (x.side == i) poly.push_back(crossingPx(x));
            }
        } else {
            for (std::uint32_t s : c.s)
                if (samples_[s].ok) poly.push_back(samples_[s].px);
        }
        raster.polygon(convexHull(std::move(poly)), e, stats);
    }
}

} // namespace ff::trace
