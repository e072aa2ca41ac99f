#include "core/install_paths.h"

#include <cstdint>
#include <cstdlib>
#include <dlfcn.h>
#include <link.h>
#include <string>
#include <system_error>

// Set by CMake (src/core/CMakeLists.txt): share/fourierflare relative to the installed bin/ and to
// the Python module's folder.
#ifndef FF_DATA_FROM_BIN
#define FF_DATA_FROM_BIN "../share/fourierflare"
#endif
#ifndef FF_DATA_FROM_PYTHON
#define FF_DATA_FROM_PYTHON "../../../share/fourierflare"
#endif

namespace ff {

namespace fs = std::filesystem;

namespace {

bool isDirectory(const fs::path& p) {
    std::error_code ec;
    return fs::is_directory(p, ec);
}

// Whether `address` lies in a loaded segment of the main program (the first object that
// dl_iterate_phdr visits), rather than in a shared object such as the Python module.
bool inMainProgram(const void* address) {
    struct Probe {
        std::uintptr_t address;
        bool inside;
    } probe{reinterpret_cast<std::uintptr_t>(address), false};
    dl_iterate_phdr(
        [](dl_phdr_info* info, std::size_t, void* data) {
            auto* p = static_cast<Probe*>(data);
            for (int i = 0; i < info->dlpi_phnum; ++i) {
                const ElfW(Phdr)& ph = info->dlpi_phdr[i];
                const std::uintptr_t lo = info->dlpi_addr + ph.p_vaddr;
                if (ph.p_type == PT_LOAD && p->address >= lo && p->address < lo + ph.p_memsz) p->inside = true;
            }
            return 1; // the first object only
        },
        &probe);
    return probe.inside;
}

// The file this code was loaded from: the executable (its name from /proc/self/exe: dladdr gives
// argv[0] for it; `executable` set), or the Python module (a shared object, named as it was loaded).
fs::path thisBinary(bool& executable) {
    std::error_code ec;
    const void* self = reinterpret_cast<const void*>(&thisBinary);
    executable = inMainProgram(self);
    if (executable) return fs::canonical("/proc/self/exe", ec);
    Dl_info info{};
    if (dladdr(self, &info) == 0 || !info.dli_fname) return {};
    const fs::path path = fs::canonical(info.dli_fname, ec);
    return ec ? fs::path() : path;
}

} // namespace

fs::path dataDirectory() {
    if (const char* dir = std::getenv("FOURIERFLARE_DATA_DIR"); dir && *dir)
        return isDirectory(dir) ? fs::path(dir) : fs::path();
    bool executable = false;
    const fs::path binary = thisBinary(executable);
    if (binary.empty()) return {};
    const fs::path data = binary.parent_path() / (executable ? FF_DATA_FROM_BIN : FF_DATA_FROM_PYTHON);
    return isDirectory(data) ? data.lexically_normal() : fs::path();
}

std::vector<fs::path> lensSearchPath() {
    std::vector<fs::path> dirs;
    if (const char* path = std::getenv("FOURIERFLARE_LENS_PATH")) {
        const std::string s(path);
        std::size_t start = 0;
        while (start <= s.size()) {
            const std::size_t end = std::min(s.find(':', start), s.size());
            if (end > start) dirs.emplace_back(s.substr(start, end - start));
            start = end + 1;
        }
    }
    if (const fs::path data = dataDirectory(); !data.empty() && isDirectory(data / "lenses"))
        dirs.push_back(data / "lenses");
    return dirs;
}

} // namespace ff
