#pragma once
// On-disk cache of ghost tables, keyed by a hash of the lens file's bytes, its zoom position and every
// table setting. Folder: $FF_CACHE_DIR, else $XDG_CACHE_HOME/fourierflare, else ~/.cache/fourierflare.
// A missing entry is built; an unreadable, corrupt or mismatching one is rebuilt (with a note), never
// trusted. Entries are written atomically.

#include "core/reporter.h"
#include "ghosts/ghost_table.h"

#include <filesystem>

namespace ff::ghosts {

std::filesystem::path cacheDirectory();
std::string cacheKey(const optics::Lens& lens, const TableSettings& settings);

/// The table for the lens and settings: from the cache when a valid entry exists, else built (and
/// stored when useCache). `fromCache` tells which happened.
GhostTable tableFor(const optics::Lens& lens, const TableSettings& settings, bool useCache, const Progress& progress,
                    Reporter& reporter, bool* fromCache = nullptr);

} // namespace ff::ghosts
