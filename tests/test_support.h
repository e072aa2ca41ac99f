#pragma once
// Helpers shared by the tests: where the repository and the shared data live, temporary folders,
// and running the CLI.

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace ff::test {

inline std::filesystem::path sourceDir() {
    return FF_SOURCE_DIR;
}
inline std::filesystem::path lensPath(const std::string& name) {
    return sourceDir() / "lenses" / name;
}
/// ../shared/data beside the repository; tests that need it skip when it is absent.
inline std::filesystem::path sharedDataDir() {
    return FF_SHARED_DATA_DIR;
}

/// A fresh temporary folder, removed when the object goes away.
class TempDir {
  public:
    TempDir() {
        std::random_device rd;
        path_ = std::filesystem::temp_directory_path() / ("fftest-" + std::to_string(rd()) + std::to_string(rd()));
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

  private:
    std::filesystem::path path_;
};

inline void writeFile(const std::filesystem::path& p, const std::string& content) {
    std::ofstream(p, std::ios::binary) << content;
}

inline std::string readFile(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Copies the zip-compressed EXR `from` to `to` with its data and display windows rewritten to
/// claim 16384 x 16384 pixels (and bytes enough for the line-offset table, so the header opens): a
/// hostile file to be refused before anything is allocated. False when a window is not found.
inline bool writeHugeHeaderCopy(const std::filesystem::path& from, const std::filesystem::path& to) {
    std::string bytes = readFile(from);
    const int huge[4] = {0, 0, 16383, 16383};
    for (const std::string& key : {std::string("dataWindow\0box2i\0", 17), std::string("displayWindow\0box2i\0", 20)}) {
        const auto at = bytes.find(key);
        if (at == std::string::npos || at + key.size() + 4 + sizeof huge > bytes.size()) return false;
        std::memcpy(&bytes[at + key.size() + 4], huge, sizeof huge);
    }
    writeFile(to, bytes + std::string(8 * 1024, '\0'));
    return true;
}

} // namespace ff::test
