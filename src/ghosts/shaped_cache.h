#pragma once
// The table cache: shaped tables on disk (with the fits derived from them in their headers), keyed by
// a hash of the lens file's bytes, its zoom position and every setting of the build, in
// ff::cacheDirectory() (core/file_io.h). A missing entry is
// built; an unreadable, corrupt, older-format or mismatching one is rebuilt with a note, never
// trusted. Entries are written atomically.
//
// Format (docs/ghost-table.md, "The table on disk"): the magic "FFSHAPED", a format version, a JSON
// header (the key, the table's scalars, the direct image's centroids, the fitted table as
// tableToJson's text, every ghost's layout and flux) with its CRC-32, then per ghost its meshes,
// one Zstandard frame with its content checksum: per wavelength the lost vertices, then each attribute quantised to
// 16 bits over its range across the angles (step (hi - lo) / 65534; 65535 marks a non-finite value),
// stored as residuals from a prediction by the previous angle and the vertices before it. Loading
// gives back every value within half a step, and NaN for every attribute of a lost ray.

#include "core/reporter.h"
#include "ghosts/ghost_table.h"
#include "ghosts/shaped_ghosts.h"

#include <filesystem>
#include <string>
#include <string_view>

namespace ff::ghosts {

/// The table as the cache stores it.
std::string shapedTableToBytes(const ShapedTable& table, const std::string& key);
/// A table from shapedTableToBytes; throws Error (ErrorKind::Input, naming `file`) when the bytes are
/// not a complete, intact entry of this format version. `key` is set to the entry's key.
ShapedTable shapedTableFromBytes(std::string_view bytes, const std::string& file, std::string& key);

/// The shaped table of the lens: from the cache when a valid entry with the same key exists, else
/// built (and stored when useCache). `fromCache` tells which happened.
ShapedTable shapedTableFor(const optics::Lens& lens, const TableSettings& settings, bool useCache, Reporter& reporter,
                           bool* fromCache = nullptr, const Progress& progress = {});

/// The fitted table of the lens: from a valid cache entry's header when there is one (the meshes are
/// not read), else the shaped table is built (and stored when useCache). `fromCache` tells which.
GhostTable tableFor(const optics::Lens& lens, const TableSettings& settings, bool useCache, const Progress& progress,
                    Reporter& reporter, bool* fromCache = nullptr);

} // namespace ff::ghosts
