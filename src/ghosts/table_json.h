#pragma once
// The ghost table as JSON: the canonical, schema-versioned format documented in docs/ghost-table.md.
// It is what `fourierflare table` and `export --format json` write and what the cache entries' headers hold.

#include "ghosts/ghost_table.h"

#include <string>

namespace ff::ghosts {

/// Indented for reading (one space per level), or on one line (compact: the cache's header).
std::string tableToJson(const GhostTable& table, bool compact = false);

/// Parses a table written by tableToJson. Throws ff::Error (Input) naming `source` when the text is
/// not such a table (bad JSON, other schema or version, missing or inconsistent fields).
GhostTable tableFromJson(const std::string& text, const std::string& source);

} // namespace ff::ghosts
