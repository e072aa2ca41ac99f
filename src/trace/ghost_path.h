#pragma once
// Light paths through a lens: the direct path, and the two-bounce ghosts. A ghost (j, i), i < j,
// transmits forward to surface j, reflects there, travels back to surface i, reflects again and then
// goes forward to the sensor. Only reflecting interfaces (an index step at the d line) take part, so
// a flat air-air stop never reflects, but every surface a path crosses clips it.

#include "optics/lens.h"

#include <optional>
#include <string>
#include <vector>

namespace ff::trace {

struct GhostPair {
    std::size_t first = 0;  ///< j: the later surface, where light reflects first (0-based)
    std::size_t second = 0; ///< i < j: where it reflects the second time
    /// "R6→R5" in 1-based surface numbers, in the order the light meets them.
    std::string label() const;
    bool operator==(const GhostPair&) const = default;
};

/// Every two-bounce ghost of the lens: m (m - 1) / 2 pairs over its m reflecting interfaces, ordered
/// by j then i.
std::vector<GhostPair> enumerateGhosts(const optics::Lens& lens);

/// One interaction of a path: cross (refract) or reflect at a surface.
struct PathStep {
    std::size_t surface = 0;
    bool reflect = false;
    bool operator==(const PathStep&) const = default;
};

/// The ordered surface interactions of the direct path (no ghost) or of a ghost.
std::vector<PathStep> pathSteps(const optics::Lens& lens, const std::optional<GhostPair>& ghost);

} // namespace ff::trace
