#pragma once
// Reading inputs defensively and writing outputs atomically.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace ff {

/// Reads a whole file as bytes. Throws ff::Error (Input) when it does not exist, is not a regular
/// file, cannot be read, or is larger than maxBytes (checked before reading).
std::string readFileBytes(const std::filesystem::path& path, std::uintmax_t maxBytes);

/// Writes content to path through a temporary file in the same folder and a rename, so readers
/// never see a partial file. Throws ff::Error (Runtime) on failure; the temporary is removed.
void writeFileAtomic(const std::filesystem::path& path, std::string_view content);

/// True when both paths name the same existing file (or the same normalised path).
bool samePath(const std::filesystem::path& a, const std::filesystem::path& b);

/// The cache folder (ghost tables, PSFs): $FF_CACHE_DIR, else $XDG_CACHE_HOME/fourierflare, else
/// ~/.cache/fourierflare, else fourierflare-cache in the system's temporary folder. Not created here.
std::filesystem::path cacheDirectory();

/// 64-bit FNV-1a hash of bytes, as 16 lowercase hex digits (used to key caches and record inputs).
std::string hashHex(std::string_view bytes);

} // namespace ff
