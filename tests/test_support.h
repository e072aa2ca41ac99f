#pragma once
// Helpers shared by the tests: where the repository and the shared data live, temporary folders,
// and running the CLI.

#include <cstdlib>
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

} // namespace ff::test
