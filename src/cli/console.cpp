#include "cli/console.h"

#include "core/text.h"

#include <cstdio>

namespace ff::cli {

void ConsoleReporter::report(const Diagnostic& d) {
    if (options_.quiet && d.severity == Severity::Note) return;
    std::fprintf(stderr, "fourierflare: %s: %s\n", d.severity == Severity::Warning ? "warning" : "note",
                 text::printable(d.str()).c_str());
}

void printError(const std::string& message) {
    std::fprintf(stderr, "fourierflare: error: %s\n", text::printable(message).c_str());
}

} // namespace ff::cli
