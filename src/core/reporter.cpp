#include "core/reporter.h"

namespace ff {

std::string Diagnostic::str() const {
    const std::string loc = where.str();
    return loc.empty() ? message : loc + ": " + message;
}

Reporter& orNull(Reporter* r) {
    static NullReporter null;
    return r ? *r : null;
}

} // namespace ff
