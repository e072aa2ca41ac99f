#include "trace/ghost_path.h"

#include "core/units.h"

namespace ff::trace {

std::string GhostPair::label() const {
    return "R" + std::to_string(first + 1) + "\u2192R" + std::to_string(second + 1);
}

std::vector<GhostPair> enumerateGhosts(const optics::Lens& lens) {
    const auto reflecting = lens.reflectingInterfaces(lines::d);
    std::vector<GhostPair> out;
    for (std::size_t a = 0; a < reflecting.size(); ++a)
        for (std::size_t b = 0; b < a; ++b) out.push_back({reflecting[a], reflecting[b]});
    return out;
}

std::vector<PathStep> pathSteps(const optics::Lens& lens, const std::optional<GhostPair>& ghost) {
    const std::size_t n = lens.surfaces.size();
    std::vector<PathStep> steps;
    if (!ghost) {
        for (std::size_t s = 0; s < n; ++s) steps.push_back({s, false});
        return steps;
    }
    const auto [j, i] = *ghost;
    for (std::size_t s = 0; s < j; ++s) steps.push_back({s, false});
    steps.push_back({j, true});
    for (std::size_t s = j - 1; s > i; --s) steps.push_back({s, false});
    steps.push_back({i, true});
    for (std::size_t s = i + 1; s < n; ++s) steps.push_back({s, false});
    return steps;
}

} // namespace ff::trace
