#pragma once
// Importer for Zemax OpticStudio sequential lens files (.zmx): UTF-16 (LE/BE, with BOM or detected)
// or UTF-8/ASCII. Reads UNIT, NAME, ENPD, and per SURF block TYPE (STANDARD, EVENASPH), CURV, DISZ,
// GLAS (by catalogue name; unknown names fall back to the inline nd/Vd with a note), DIAM/CLAP,
// STOP, CONI, PARM (even-asphere terms), COAT. Unknown directives are ignored and counted in a note;
// structural problems (no surfaces, no stop, unsupported surface types, mirrors) are errors with
// file:line:column.

#include "core/reporter.h"
#include "optics/lens.h"

#include <string>
#include <string_view>

namespace ff::optics {

/// Converts raw .zmx bytes to UTF-8 (UTF-16 with or without BOM, or UTF-8 with optional BOM).
std::string decodeZmxText(std::string_view bytes, const std::string& fileName);

Lens importZmx(std::string_view bytes, const std::string& fileName, Reporter* reporter = nullptr);

} // namespace ff::optics
