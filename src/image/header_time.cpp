#include "image/header_time.h"

#include "core/error.h"

#include <cerrno>
#include <cstdlib>
#include <ctime>

namespace ff::image {

std::string headerDateTime() {
    const char* epoch = std::getenv("SOURCE_DATE_EPOCH");
    if (!epoch || !*epoch) return ""; // unset or empty: no time stamp
    const std::string text(epoch);
    char* end = nullptr;
    errno = 0;
    const long long seconds = std::strtoll(text.c_str(), &end, 10);
    // Up to the year 9999: the header's field has four digits for the year.
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || errno != 0 || *end != '\0' ||
        seconds > 253402300799LL)
        throw Error(ErrorKind::Usage, "SOURCE_DATE_EPOCH must be seconds since 1970-01-01 UTC (digits, up to "
                                      "253402300799), got '" +
                                          text + "'");
    const std::time_t t = static_cast<std::time_t>(seconds);
    std::tm utc{};
    gmtime_r(&t, &utc);
    char buffer[32];
    std::strftime(buffer, sizeof buffer, "%Y:%m:%d %H:%M:%S", &utc);
    return buffer;
}

} // namespace ff::image
