#pragma once
// Reading inputs defensively and writing outputs atomically.

#include "core/reporter.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace ff {

/// Reads a whole file as bytes. Throws ff::Error (Input) when it does not exist, is not a regular
/// file, cannot be read, or is larger than maxBytes (checked before reading).
std::string readFileBytes(const std::filesystem::path& path, std::uintmax_t maxBytes);

/// Writes content to path through a temporary file in the same folder (.NAME.tmpPID-N) and a
/// rename, so readers never see a partial file. Throws ff::Error (Runtime) with the system's reason
/// on failure; the temporary is removed (a process killed meanwhile leaves it, hidden).
void writeFileAtomic(const std::filesystem::path& path, std::string_view content);

/// Whether `folder` may be replaced by writeFolderAtomic: it does not exist, or it is an empty folder,
/// or a folder holding the file `marker` (an earlier output of the same kind).
bool replaceableFolder(const std::filesystem::path& folder, const std::string& marker);

/// Writes files (paths relative to `folder`, their parent folders created) into a hidden folder
/// beside `folder` (.NAME.tmpPID-N), then puts it in place with renames, so readers see the whole
/// old folder or the whole new one. The caller checks replaceableFolder first. Throws ff::Error
/// (Runtime) with the system's reason on failure, after removing what it wrote.
void writeFolderAtomic(const std::filesystem::path& folder,
                       const std::vector<std::pair<std::string, std::string>>& files);

/// Stores a cache entry with writeFileAtomic, creating its folder: readers never see a partial
/// entry, and processes storing the same entry at once leave one whole entry (the last rename).
/// Never throws: a folder that cannot be created or written (read-only, another user's) gets a note,
/// a failed write (a full disk) a warning; the caller keeps what it built in memory. `what` names
/// the entry in messages ("shaped table").
void storeCacheEntry(const std::filesystem::path& file, std::string_view bytes, const std::string& what,
                     Reporter& reporter);

/// True when both paths name the same existing file (or the same normalised path).
bool samePath(const std::filesystem::path& a, const std::filesystem::path& b);

/// The cache folder (ghost tables, PSFs): $FF_CACHE_DIR, else $XDG_CACHE_HOME/fourierflare, else
/// ~/.cache/fourierflare, else fourierflare-cache in the system's temporary folder. Not created here.
std::filesystem::path cacheDirectory();

/// 64-bit FNV-1a hash of bytes, as 16 lowercase hex digits (used to key caches and record inputs).
std::string hashHex(std::string_view bytes);

} // namespace ff
