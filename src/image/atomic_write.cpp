#include "image/atomic_write.h"

#include "core/error.h"
#include "image/header_time.h"

#include <filesystem>
#include <random>

namespace ff::image {

namespace fs = std::filesystem;

namespace {

// A temporary name in the target's folder that keeps its extension (OpenImageIO picks the format
// from it).
fs::path temporaryFor(const fs::path& target) {
    std::random_device rd;
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    return dir / ("." + target.stem().string() + ".tmp" + std::to_string(rd() % 1000000) + target.extension().string());
}

} // namespace

void writeAtomic(const std::string& path, const OIIO::ImageSpec& given, OIIO::TypeDesc type, const void* data) {
    // The header's time stamp: the given one (a plate's), else SOURCE_DATE_EPOCH's, else none (an
    // empty DateTime is left out; without one, OpenImageIO's EXR writer stamps the time of writing).
    OIIO::ImageSpec spec = given;
    if (spec.get_string_attribute("DateTime").empty()) spec.attribute("DateTime", headerDateTime());
    const fs::path target(path);
    const fs::path tmp = temporaryFor(target);
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) throwRuntimeError("cannot write '" + path + "': " + OIIO::geterror());
    if (!out->open(tmp.string(), spec) || !out->write_image(type, data) || !out->close()) {
        const std::string err = out->geterror();
        out.reset();
        std::error_code ec;
        fs::remove(tmp, ec);
        throwRuntimeError("cannot write '" + path + "': " + err);
    }
    out.reset();
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throwRuntimeError("cannot write '" + path + "': " + ec.message());
    }
}

} // namespace ff::image
