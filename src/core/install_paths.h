#pragma once
// Where an installed fourierflare finds its bundled data (docs/install.md): lenses/, glass/ and
// plates/ under <prefix>/share/fourierflare, found from the program's own location (the executable,
// or the Python module holding this code), so that an installed tree can be moved or unpacked
// anywhere (a .deb into a scratch root) and still find its data.

#include <filesystem>
#include <vector>

namespace ff {

/// The bundled data folder: $FOURIERFLARE_DATA_DIR when set and not empty; else the install's
/// share/fourierflare reached from the folder of the binary holding this code (the relative paths
/// from bin/ and from the Python module's folder are fixed when the project is configured); empty
/// when neither exists (a build tree).
std::filesystem::path dataDirectory();

/// The folders searched for a lens given by name, in order: each of $FOURIERFLARE_LENS_PATH
/// (colon-separated), then dataDirectory()/lenses when it exists.
std::vector<std::filesystem::path> lensSearchPath();

} // namespace ff
