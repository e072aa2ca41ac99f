#pragma once
// The reporting interface through which libraries tell the caller what they decided or noticed
// (a tolerated quirk in a lens file, a clamped value, progress of long work). Libraries never print;
// the CLI implements Reporter to own the terminal, tests collect messages.

#include "core/error.h"

#include <string>
#include <vector>

namespace ff {

enum class Severity { Note, Warning };

struct Diagnostic {
    Severity severity = Severity::Note;
    SourceLocation where;
    std::string message;

    /// "file:line:col: message" (location omitted when unknown).
    std::string str() const;
};

class Reporter {
  public:
    virtual ~Reporter() = default;
    virtual void report(const Diagnostic& d) = 0;

    void note(const SourceLocation& where, const std::string& message) { report({Severity::Note, where, message}); }
    void warning(const SourceLocation& where, const std::string& message) {
        report({Severity::Warning, where, message});
    }
};

/// Discards everything; the default where a caller passes no reporter.
class NullReporter final : public Reporter {
  public:
    void report(const Diagnostic&) override {}
};

/// Keeps every diagnostic, in order (tests, and callers that show them later).
class CollectingReporter final : public Reporter {
  public:
    void report(const Diagnostic& d) override { diagnostics.push_back(d); }
    std::vector<Diagnostic> diagnostics;
};

/// Returns r itself, or a process-wide NullReporter when r is null.
Reporter& orNull(Reporter* r);

} // namespace ff
