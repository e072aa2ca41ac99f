#include "trace/lit_points.h"

#include "trace/embree_tracer.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace ff::trace {

namespace {

// A fixed pseudo-random place in cell (i, j), within +-0.45 of a cell of its centre along each axis;
// passes with different seeds place their points independently.
glm::dvec2 jitter(int i, int j, std::uint32_t seed) {
    std::uint32_t h = (static_cast<std::uint32_t>(i) * 0x9E3779B1u ^ static_cast<std::uint32_t>(j) * 0x85EBCA77u) +
                      seed * 0xC2B2AE3Du;
    const auto next = [&h] {
        h ^= h >> 16, h *= 0x7FEB352Du, h ^= h >> 15, h *= 0x846CA68Bu, h ^= h >> 16;
        return (h >> 8) * (1.0 / 16777216.0) - 0.5;
    };
    const double x = next();
    return {0.9 * x, 0.9 * next()};
}

// The box of one lit point.
LitBox pointBox(const LitGrid& g, int i, int j) {
    LitBox box;
    const glm::dvec2 p = g.point(i, j);
    box.xMin = box.xMax = p.x;
    box.yMin = box.yMax = p.y;
    box.touchesEdge = i == 0 || j == 0 || i == g.b.n - 1 || j == g.b.n - 1;
    box.litArea = g.b.cell * g.b.cell;
    box.litPoints = 1;
    box.thinPoints = (!g.at(i - 1, j) && !g.at(i + 1, j)) || (!g.at(i, j - 1) && !g.at(i, j + 1));
    return box;
}

} // namespace

// Traces b's points (moved by their jitter, if a seed is given) and marks those lit.
LitGrid litGrid(Bundle b, const LensAtWavelength& L, const std::vector<PathStep>& steps, double maxRadius,
                std::optional<std::uint32_t> jitterSeed) {
    LitGrid g{std::move(b), {}, {}};
    if (jitterSeed) {
        g.offsets.resize(g.b.rays.size());
        for (int j = 0; j < g.b.n; ++j)
            for (int i = 0; i < g.b.n; ++i) {
                const std::size_t k = static_cast<std::size_t>(j) * g.b.n + i;
                g.offsets[k] = jitter(i, j, *jitterSeed);
                // The rays are parallel: moving a point of the pupil plane moves its ray's origin alike.
                g.b.rays[k].origin.x += g.offsets[k].x * g.b.cell;
                g.b.rays[k].origin.y += g.offsets[k].y * g.b.cell;
            }
    }
    std::vector<RayResult> hits(g.b.rays.size());
    traceAnalytic(L, steps, g.b.rays, hits, Weighting::None); // where light gets through, not how much
    g.lit.assign(hits.size(), 0);
    for (std::size_t k = 0; k < hits.size(); ++k) {
        const RayResult& r = hits[k];
        g.lit[k] = r.status == optics::RayStatus::Ok &&
                   (maxRadius <= 0.0 || std::hypot(r.sensorPoint.x, r.sensorPoint.y) <= maxRadius);
    }
    return g;
}

LitBox litBox(const LitGrid& g) {
    LitBox box;
    for (int j = 0; j < g.b.n; ++j)
        for (int i = 0; i < g.b.n; ++i)
            if (g.at(i, j)) box.add(pointBox(g, i, j));
    return box;
}

std::vector<glm::dvec2> litPlaces(const LitGrid& g) {
    std::vector<glm::dvec2> places;
    for (int j = 0; j < g.b.n; ++j)
        for (int i = 0; i < g.b.n; ++i)
            if (g.at(i, j)) places.push_back(g.point(i, j));
    return places;
}

std::vector<LitBox> litPieces(const LitGrid& g, std::size_t maxPieces) {
    std::vector<LitBox> pieces;
    std::vector<char> seen(g.lit.size(), 0);
    std::vector<std::pair<int, int>> stack;
    for (int j0 = 0; j0 < g.b.n; ++j0)
        for (int i0 = 0; i0 < g.b.n; ++i0) {
            if (!g.at(i0, j0) || seen[static_cast<std::size_t>(j0) * g.b.n + i0]) continue;
            if (pieces.size() == maxPieces) return {};
            LitBox piece;
            seen[static_cast<std::size_t>(j0) * g.b.n + i0] = 1;
            stack.assign(1, {i0, j0});
            while (!stack.empty()) {
                const auto [i, j] = stack.back();
                stack.pop_back();
                piece.add(pointBox(g, i, j));
                for (int dj = -1; dj <= 1; ++dj)
                    for (int di = -1; di <= 1; ++di) {
                        const std::size_t k = static_cast<std::size_t>(j + dj) * g.b.n + (i + di);
                        if (!g.at(i + di, j + dj) || seen[k]) continue;
                        seen[k] = 1;
                        stack.push_back({i + di, j + dj});
                    }
            }
            pieces.push_back(piece);
        }
    return pieces;
}

// The boxes' gap: how far apart they lie along x or y (negative where they overlap along both).
double gap(const LitBox& a, const LitBox& b) {
    return std::max(std::max(a.xMin - b.xMax, b.xMin - a.xMax), std::max(a.yMin - b.yMax, b.yMin - a.yMax));
}

// Merges boxes lying closer than minGap into one, until none do.
} // namespace ff::trace
