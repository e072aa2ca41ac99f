#include "ghosts/table_cache.h"

#include "core/error.h"
#include "core/file_io.h"
#include "ghosts/table_json.h"

#include <cstdlib>

namespace fs = std::filesystem;

namespace ff::ghosts {

fs::path cacheDirectory() {
    if (const char* d = std::getenv("FF_CACHE_DIR"); d && *d) return d;
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return fs::path(x) / "fourierflare";
    if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "fourierflare";
    return fs::temp_directory_path() / "fourierflare-cache";
}

std::string cacheKey(const optics::Lens& lens, const TableSettings& s) {
    return hashHex(lens.contentHash + "|zoom " + std::to_string(lens.activeZoom) + "|" + s.key());
}

GhostTable tableFor(const optics::Lens& lens, const TableSettings& s, bool useCache, const Progress& progress,
                    Reporter& reporter, bool* fromCache) {
    if (fromCache) *fromCache = false;
    const std::string key = cacheKey(lens, s);
    const fs::path file = cacheDirectory() / (key + ".ghosts.json");
    if (useCache && fs::exists(file)) {
        try {
            GhostTable t = tableFromJson(readFileBytes(file, 1u << 30), file.string());
            if (t.lensHash == lens.contentHash && t.settingsKey == s.key()) {
                if (fromCache) *fromCache = true;
                return t;
            }
            reporter.note({file.string()}, "cached ghost table does not match the lens or settings; rebuilding it");
        } catch (const Error& e) {
            reporter.note({file.string()},
                          std::string("cached ghost table is unreadable (") + e.message() + "); rebuilding it");
        }
    }
    GhostTable t = buildGhostTable(lens, s, progress);
    if (useCache) {
        std::error_code ec;
        fs::create_directories(file.parent_path(), ec);
        try {
            writeFileAtomic(file, tableToJson(t));
        } catch (const Error& e) {
            reporter.warning({file.string()},
                             std::string("could not store the ghost table in the cache: ") + e.message());
        }
    }
    return t;
}

} // namespace ff::ghosts
