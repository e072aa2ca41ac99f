#pragma once
// Errors carry where they happened (file:line:column when the cause is in an input file) and what
// kind of failure they are, so the CLI can print one precise line and pick the exit code.
// Libraries throw ff::Error; they never print or exit.

#include <stdexcept>
#include <string>

namespace ff {

/// A place in an input file. line and column are 1-based; 0 means "not known / whole file".
struct SourceLocation {
    std::string file;
    int line = 0;
    int column = 0;

    bool empty() const { return file.empty() && line == 0; }
    /// "file:line:col", "file:line", "file" or "" depending on what is known.
    std::string str() const;
};

enum class ErrorKind {
    Input,   ///< malformed or unusable input data (exit code 2)
    Usage,   ///< bad command-line usage (exit code 2)
    Runtime, ///< the work itself failed: I/O, numerical failure, missing device (exit code 1)
};

class Error : public std::runtime_error {
  public:
    Error(ErrorKind kind, SourceLocation where, const std::string& message);
    Error(ErrorKind kind, const std::string& message) : Error(kind, {}, message) {}

    ErrorKind kind() const { return kind_; }
    const SourceLocation& where() const { return where_; }
    /// The message without the location prefix.
    const std::string& message() const { return message_; }

  private:
    ErrorKind kind_;
    SourceLocation where_;
    std::string message_;
};

/// Shorthands for the common case of bad input at a known place.
[[noreturn]] void throwInputError(const SourceLocation& where, const std::string& message);
[[noreturn]] void throwRuntimeError(const std::string& message);

/// Exit code the CLI maps an error kind to (see docs/cli.md).
int exitCodeFor(ErrorKind kind);

} // namespace ff
