#pragma once
// Reader of the native `.lens` format: the FlareSim-family format read as is, plus the extensions
// documented in docs/lens-format.md. Parsing is strict: any malformed line throws ff::Error (Input)
// with file:line:column and what was expected; tolerated quirks (semi_ap 0, ...) are reported as
// notes through the Reporter, never skipped silently.

#include "core/reporter.h"
#include "optics/lens.h"

#include <string>
#include <string_view>

namespace ff::optics {

/// Parses lens text. fileName is used in messages only. The result has its zoom position 0 active
/// and an 'auto' image distance resolved; it is validated (one stop, sane values).
Lens parseLensText(std::string_view text, const std::string& fileName, Reporter* reporter = nullptr);

/// Rejects bytes that cannot be lens text (NUL bytes, control characters, invalid UTF-8), with the
/// line and column of the first offender. Shared by the text importers.
void checkIsText(std::string_view text, const std::string& fileName);

} // namespace ff::optics
