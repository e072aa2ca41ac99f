#pragma once
// What the lens-format fuzz targets share: parse the bytes as one format; a lens that parses is
// analysed (first order at the d line) and written as .lens, which must parse again. A reader may
// only return a lens or throw ff::Error; any other exception escapes and libFuzzer reports it.

#include "core/error.h"
#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "optics/lens_writer.h"
#include "optics/paraxial.h"

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace ff::fuzz {

inline void lensFormat(const std::uint8_t* data, std::size_t size, const char* format) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    try {
        const optics::Lens lens = optics::parseLensBytes(bytes, format, "fuzz");
        try {
            (void)optics::analyzeFirstOrder(lens, lines::d);
        } catch (const Error&) {
            // e.g. an afocal system: a precise error is a valid outcome.
        }
        (void)optics::parseLensText(optics::writeLensText(lens), "fuzz-roundtrip");
    } catch (const Error&) {
    }
}

} // namespace ff::fuzz
