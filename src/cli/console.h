#pragma once
// The CLI's side of reporting: diagnostics from the libraries go to stderr as
// "fourierflare: note: file:line:col: ..." unless --quiet.

#include "core/reporter.h"

#include <string>
#include <vector>

namespace ff::cli {

/// Options shared by every command.
struct GlobalOptions {
    bool quiet = false;
    bool verbose = false;               ///< print every choice (Fourier plan, stage times)
    std::string commandLine;            ///< as typed, less --threads N, -q, -v: recorded in outputs
    std::vector<std::string> arguments; ///< the words of commandLine
};

class ConsoleReporter final : public Reporter {
  public:
    explicit ConsoleReporter(const GlobalOptions& options) : options_(options) {}
    void report(const Diagnostic& d) override;

  private:
    const GlobalOptions& options_;
};

/// Prints "fourierflare: error: <message>" to stderr.
void printError(const std::string& message);

} // namespace ff::cli
