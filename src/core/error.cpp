#include "core/error.h"

namespace ff {

std::string SourceLocation::str() const {
    std::string s = file;
    if (line > 0) {
        s.append(1, ':').append(std::to_string(line));
        if (column > 0) s.append(1, ':').append(std::to_string(column));
    }
    return s;
}

static std::string withLocation(const SourceLocation& where, const std::string& message) {
    const std::string loc = where.str();
    return loc.empty() ? message : loc + ": " + message;
}

Error::Error(ErrorKind kind, SourceLocation where, const std::string& message)
    : std::runtime_error(withLocation(where, message)), kind_(kind), where_(std::move(where)), message_(message) {}

void throwInputError(const SourceLocation& where, const std::string& message) {
    throw Error(ErrorKind::Input, where, message);
}

void throwRuntimeError(const std::string& message) {
    throw Error(ErrorKind::Runtime, message);
}

int exitCodeFor(ErrorKind kind) {
    switch (kind) {
    case ErrorKind::Input:
    case ErrorKind::Usage:
        return 2;
    case ErrorKind::Runtime:
        return 1;
    }
    return 1;
}

} // namespace ff
