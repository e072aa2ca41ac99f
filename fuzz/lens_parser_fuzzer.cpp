// libFuzzer target for the lens readers: every input is parsed as a native .lens file, as a Zemax
// .zmx file and as a pbrt .dat file. A reader may only return a lens or throw ff::Error; anything
// else (another exception, a crash, a sanitizer report, a hang) is a bug. Parsed lenses also go
// through first-order analysis and the writer, whose output must parse again.

#include "core/error.h"
#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/lens_writer.h"
#include "optics/paraxial.h"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    for (const char* format : {"lens", "zmx", "dat"}) {
        try {
            const ff::optics::Lens lens = ff::optics::parseLensBytes(bytes, format, "fuzz");
            try {
                (void)ff::optics::analyzeFirstOrder(lens, ff::lines::d);
            } catch (const ff::Error&) {
                // e.g. an afocal system: a precise error is a valid outcome.
            }
            (void)ff::optics::parseLensText(ff::optics::writeLensText(lens), "fuzz-roundtrip");
        } catch (const ff::Error&) {
        }
    }
    return 0;
}
