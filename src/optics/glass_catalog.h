#pragma once
// The glass catalogue: named media with Sellmeier coefficients, read from the files in data/glass/
// (embedded into the binary at build time). Lookups are case-insensitive; an unknown name throws
// with the closest known names.

#include "core/error.h"
#include "optics/medium.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace ff::optics {

struct GlassEntry {
    std::string name;
    Dispersion dispersion;
    double catalogNd = 0.0; ///< value printed in the catalogue (0 when it gives none)
    double catalogVd = 0.0;
    std::string source; ///< catalogue file it came from
};

class GlassCatalog {
  public:
    /// The built-in catalogue (SCHOTT glasses + coating materials), parsed once.
    static const GlassCatalog& builtin();

    /// Parses catalogue text in the format documented in data/glass/schott.glass. Throws
    /// ff::Error (Input) with file:line:column on malformed lines.
    void addFromText(std::string_view text, const std::string& sourceName);

    /// Finds a glass by name (case-insensitive, aliases resolved); nullptr when unknown.
    const GlassEntry* find(std::string_view name) const;
    /// Like find, but an unknown name throws ff::Error (Input) at `where`, listing the closest names.
    const GlassEntry& get(std::string_view name, const SourceLocation& where) const;
    /// A Medium for the named glass (nd, Vd derived from the Sellmeier model).
    Medium medium(std::string_view name, const SourceLocation& where) const;

    std::vector<std::string> names() const;
    const std::vector<GlassEntry>& entries() const { return entries_; }

  private:
    std::vector<GlassEntry> entries_;
    std::vector<std::pair<std::string, std::string>> aliases_; // (alias, target)
};

} // namespace ff::optics
