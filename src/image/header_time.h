#pragma once
// The time stamp written into image headers, made reproducible.

#include <string>

namespace ff::image {

/// The time stamp image headers carry ("DateTime", EXR's capDate): SOURCE_DATE_EPOCH (seconds since
/// 1970-01-01 UTC, https://reproducible-builds.org/specs/source-date-epoch/) as "YYYY:MM:DD HH:MM:SS"
/// UTC when the variable is set and not empty, "" (no time stamp) otherwise, so that the same command on the same
/// inputs writes the same bytes. A DateTime in `metadata` (a plate's own) is kept. Throws ff::Error
/// (Usage) when the variable is set to anything but a non-negative integer.
std::string headerDateTime();

} // namespace ff::image
