// libFuzzer target for the ghost table's JSON (`table -o`, docs/ghost-table.md): a table or
// ff::Error, nothing else. A table it returns is written again and must read back the same.

#include "core/error.h"
#include "ghosts/table_json.h"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const ff::ghosts::GhostTable t =
            ff::ghosts::tableFromJson(std::string(reinterpret_cast<const char*>(data), size), "fuzz");
        const std::string again = ff::ghosts::tableToJson(t);
        if (ff::ghosts::tableToJson(ff::ghosts::tableFromJson(again, "fuzz-roundtrip")) != again) std::abort();
    } catch (const ff::Error&) {
    }
    return 0;
}
