#include "core/file_io.h"

#include "core/error.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <random>
#include <unistd.h>

namespace fs = std::filesystem;

namespace ff {

std::string readFileBytes(const fs::path& path, std::uintmax_t maxBytes) {
    const SourceLocation where{path.string()};
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throwInputError(where, "no such file");
    if (fs::is_directory(status)) throwInputError(where, "is a directory, expected a file");
    if (!fs::is_regular_file(status)) throwInputError(where, "is not a regular file");
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) throwInputError(where, "cannot determine the file size: " + ec.message());
    if (size > maxBytes)
        throwInputError(where, "file is " + std::to_string(size) + " bytes, larger than the limit of " +
                                   std::to_string(maxBytes) + " bytes for this kind of input");
    std::ifstream in(path, std::ios::binary);
    if (!in) throwInputError(where, "cannot open the file for reading");
    std::string bytes(static_cast<std::size_t>(size), '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(size));
    if (static_cast<std::uintmax_t>(in.gcount()) != size) throwInputError(where, "could not read the whole file");
    return bytes;
}

void writeFileAtomic(const fs::path& path, std::string_view content) {
    const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
    std::random_device rd;
    const fs::path tmp = dir / ("." + path.filename().string() + ".tmp" + std::to_string(getpid()) + "-" +
                                std::to_string(rd() % 1000000));
    auto fail = [&](const std::string& why) {
        ::unlink(tmp.c_str());
        throwRuntimeError("cannot write '" + path.string() + "': " + why);
    };
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0)
        throwRuntimeError("cannot write '" + path.string() + "': cannot create a file in '" + dir.string() +
                          "': " + std::strerror(errno));
    for (std::size_t done = 0; done < content.size();) {
        const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int e = n < 0 ? errno : EIO;
            ::close(fd);
            fail(std::strerror(e));
        }
        done += static_cast<std::size_t>(n);
    }
    if (::close(fd) != 0) fail(std::strerror(errno));
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) fail(ec.message());
}

bool replaceableFolder(const fs::path& folder, const std::string& marker) {
    std::error_code ec;
    const fs::file_status st = fs::symlink_status(folder, ec);
    if (!fs::exists(st)) return true;
    if (!fs::is_directory(st)) return false;
    return fs::is_empty(folder, ec) || fs::is_regular_file(fs::symlink_status(folder / marker, ec));
}

void writeFolderAtomic(const fs::path& folder, const std::vector<std::pair<std::string, std::string>>& files) {
    const fs::path parent = folder.has_parent_path() ? folder.parent_path() : fs::path(".");
    std::random_device rd;
    const std::string tag = std::to_string(getpid()) + "-" + std::to_string(rd() % 1000000);
    const fs::path name = folder.filename().empty() ? folder.parent_path().filename() : folder.filename();
    const fs::path tmp = parent / ("." + name.string() + ".tmp" + tag),
                   old = parent / ("." + name.string() + ".old" + tag);
    auto fail = [&](const std::string& why) {
        std::error_code ignored;
        fs::remove_all(tmp, ignored);
        throwRuntimeError("cannot write '" + folder.string() + "': " + why);
    };
    std::error_code ec;
    if (!fs::create_directory(tmp, ec)) fail("cannot create a folder in '" + parent.string() + "': " + ec.message());
    try {
        for (const auto& [path, content] : files) {
            fs::create_directories((tmp / path).parent_path());
            writeFileAtomic(tmp / path, content);
        }
    } catch (const std::exception& e) {
        fail(e.what());
    }
    const fs::path target = folder.filename().empty() ? folder.parent_path() : folder;
    const bool existed = fs::exists(fs::symlink_status(target, ec));
    if (existed) {
        fs::rename(target, old, ec);
        if (ec) fail(ec.message());
    }
    fs::rename(tmp, target, ec);
    if (ec) {
        std::error_code ignored;
        if (existed) fs::rename(old, target, ignored);
        fail(ec.message());
    }
    if (existed) fs::remove_all(old, ec);
}

void storeCacheEntry(const fs::path& file, std::string_view bytes, const std::string& what, Reporter& reporter) {
    const fs::path dir = file.parent_path();
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || ::faccessat(AT_FDCWD, dir.c_str(), W_OK | X_OK, AT_EACCESS) != 0) {
        const std::string why = ec ? ec.message() : std::strerror(errno);
        reporter.note({}, "the cache folder " + dir.string() + " is not writable (" + why + "): the " + what +
                              " was built in memory and not stored");
        return;
    }
    try {
        writeFileAtomic(file, bytes);
    } catch (const Error& e) {
        reporter.warning({file.string()}, "could not store the " + what + " in the cache: " + e.message());
    }
}

fs::path cacheDirectory() {
    if (const char* d = std::getenv("FF_CACHE_DIR"); d && *d) return d;
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return fs::path(x) / "fourierflare";
    if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "fourierflare";
    return fs::temp_directory_path() / "fourierflare-cache";
}

bool samePath(const fs::path& a, const fs::path& b) {
    std::error_code ec;
    if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
    return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

std::string hashHex(std::string_view bytes) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (unsigned char c : bytes) {
        h ^= c;
        h *= 0x100000001b3ULL;
    }
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
}

} // namespace ff
