#pragma once
// Option values the commands share: pairs of numbers ("X,Y", "WxH"), frame sizes in pixels and sensor
// sizes in millimetres. Bad values throw ff::Error (Usage) quoting what was given.

#include <string>
#include <utility>

namespace ff::cli {

/// "A<sep>B" as two finite numbers; `what` names the expected form in the message.
std::pair<double, double> parsePair(const std::string& s, char sep, const char* what);

/// "WIDTHxHEIGHT" in whole pixels, each within [lo, hi]; `option` names it in the message.
std::pair<int, int> parseFrameSize(const std::string& s, const char* option, int lo, int hi);

/// A source's field angle "DEG[,AZ]" in degrees, 0 <= DEG < 89, the azimuth 0 when not given (0: the
/// direct image at +y, counter-clockwise); `option` names it in the message.
std::pair<double, double> parseAngle(const std::string& s, const char* option);

/// "WIDTHxHEIGHT" in millimetres, each positive and at most 1000.
std::pair<double, double> parseSensorSize(const std::string& s, const char* option);

} // namespace ff::cli
