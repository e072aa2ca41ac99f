#pragma once
// Fixed-size values in and out of byte strings, in the machine's byte order: the cache entries
// (ghost tables, PSFs). A short read throws ff::Error (Input) naming the file.

#include "core/error.h"

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace ff {

template <class T>
void putBytes(std::string& out, T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    out.append(b, sizeof(T));
}

struct ByteReader {
    std::string_view bytes;
    std::size_t at = 0;
    const std::string& file;
    const char* truncated; ///< the error's message on a short read

    template <class T>
    T get() {
        if (bytes.size() - at < sizeof(T)) throw Error(ErrorKind::Input, SourceLocation{file}, truncated);
        T v;
        std::memcpy(&v, bytes.data() + at, sizeof(T));
        at += sizeof(T);
        return v;
    }
    std::string_view take(std::uint64_t n) {
        if (bytes.size() - at < n) throw Error(ErrorKind::Input, SourceLocation{file}, truncated);
        const std::string_view s = bytes.substr(at, static_cast<std::size_t>(n));
        at += static_cast<std::size_t>(n);
        return s;
    }
};

} // namespace ff
