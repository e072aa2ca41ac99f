// libFuzzer target for the cache entries (docs/farm.md): a shaped table (.shaped: header JSON,
// per-ghost meshes in Zstandard frames with their checksums) and a PSF (.psf). Each input is read as both; a reader may
// only return an entry or throw ff::Error. The cache reads whatever is in its folder, so a damaged
// or hostile entry must be refused, never crash, hang or exhaust memory.

#include "core/error.h"
#include "diffraction/psf_cache.h"
#include "ghosts/shaped_cache.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    std::string key;
    try {
        (void)ff::ghosts::shapedTableFromBytes(bytes, "fuzz.shaped", key);
    } catch (const ff::Error&) {
    }
    try {
        (void)ff::diffraction::psfFromBytes(bytes, "fuzz.psf", key);
    } catch (const ff::Error&) {
    }
    return 0;
}
