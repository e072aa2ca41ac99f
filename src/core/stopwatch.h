#pragma once
// Wall-clock times of the stages the tools report (steady clock, seconds).

#include <chrono>

namespace ff {

using Clock = std::chrono::steady_clock;

/// Seconds since `t`.
inline double secondsSince(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

/// Seconds since `t`, and `t` moved to now: the time of one stage of several in a row.
inline double lap(Clock::time_point& t) {
    const auto now = Clock::now();
    const double s = std::chrono::duration<double>(now - t).count();
    t = now;
    return s;
}

} // namespace ff
