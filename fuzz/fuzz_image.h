#pragma once
// What the image fuzz targets share: the input bytes as a file (the image library reads files, and
// picks the reader by the name's extension first, then by the bytes), one per process, removed at
// exit; and the limits the targets read with, small enough for libFuzzer's 2 GB memory bound.

#include "image/image_output.h"
#include "image/plate.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>

namespace ff::fuzz {

/// A file of this process's, `NAME-PID.exr` in $TMPDIR (else /tmp), removed at exit.
inline const std::string& scratchFile(const char* name) {
    static std::string path;
    if (path.empty()) {
        const char* dir = std::getenv("TMPDIR");
        path = std::string(dir && *dir ? dir : "/tmp") + "/" + name + "-" + std::to_string(getpid()) + ".exr";
        std::atexit([] { std::remove(path.c_str()); });
    }
    return path;
}

/// Writes the bytes to the scratch file and returns its path.
inline const std::string& asFile(const std::uint8_t* data, std::size_t size, const char* name) {
    const std::string& path = scratchFile(name);
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f || std::fwrite(data, 1, size, f) != size || std::fclose(f) != 0) std::abort();
    return path;
}

/// One thread for the EXR codec: the library's pool costs more than a fuzzed file's decoding.
inline void oneThread() {
    image::setExrThreads(1);
}

/// 2^20 pixels of at most 16 channels: 64 MB as float, far below the 2 GB bound.
inline image::PlateLimits smallLimits() {
    image::PlateLimits limits;
    limits.maxPixels = 1u << 20;
    limits.maxChannels = 16;
    return limits;
}

} // namespace ff::fuzz
