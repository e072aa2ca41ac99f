// Checked integers from JSON (nlohmann::json). Header-only: the includer links nlohmann_json.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace ff {

// The value of `v` as the integer type T. nlohmann's get<T>() converts any number with static_cast,
// which is undefined behaviour for a float outside T's range (1e308 as int) and wraps an integer that
// does not fit. This accepts an integer, or a float with an integral value, within T's range, and
// otherwise throws nlohmann's type_error (id 302, as get<T>() does for a string), which the readers
// already turn into their input errors.
template <typename T>
T jsonInteger(const nlohmann::json& v) {
    static_assert(std::is_integral_v<T> && !std::is_same_v<T, bool>);
    if (v.is_number_unsigned()) {
        if (const auto u = v.get<std::uint64_t>(); std::in_range<T>(u)) return static_cast<T>(u);
    } else if (v.is_number_integer()) {
        if (const auto i = v.get<std::int64_t>(); std::in_range<T>(i)) return static_cast<T>(i);
    } else if (v.is_number_float()) {
        // T's range as doubles: [min, 2^digits) holds exactly for every integer type.
        const double d = v.get<double>(), hi = std::ldexp(1.0, std::numeric_limits<T>::digits);
        const double lo = std::is_signed_v<T> ? -hi : 0.0;
        if (std::isfinite(d) && d == std::trunc(d) && d >= lo && d < hi) return static_cast<T>(d);
    }
    throw nlohmann::json::type_error::create(302,
                                             "expected an integer from " +
                                                 std::to_string(std::numeric_limits<T>::min()) + " to " +
                                                 std::to_string(std::numeric_limits<T>::max()) + ", got " + v.dump(),
                                             &v);
}

// An array of integers, each as jsonInteger<T>.
template <typename T>
std::vector<T> jsonIntegers(const nlohmann::json& v) {
    if (!v.is_array())
        throw nlohmann::json::type_error::create(302, "expected an array of integers, got " + v.dump(), &v);
    std::vector<T> out;
    out.reserve(v.size());
    for (const nlohmann::json& e : v) out.push_back(jsonInteger<T>(e));
    return out;
}

} // namespace ff
