#pragma once
// The command line's one convention (docs/cli.md, "Convention"): the same option name means the same
// thing in every command. These helpers add the spellings every command shares.

#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>

namespace ff::cli {

/// The lens a command works on: the first positional argument LENS, or --lens FILE (the same; give
/// one). Commands check it with requireLens before they run.
void addLensArgument(CLI::App& cmd, std::string& lens, const std::string& help = "Lens file (.lens, .zmx or .dat)");

/// Throws ff::Error (Usage) when no lens was given.
void requireLens(const std::string& lens);

/// An option's old spelling, accepted for one release: it sets `target` as `now` does and prints a
/// warning naming `now` (not hidden by --quiet: the spelling will stop working). Hidden from the help.
template <class T>
CLI::Option* addDeprecated(CLI::App& cmd, const std::string& old, T& target, const std::string& now) {
    return cmd.add_option(old, target)->group("")->each([old, now](const std::string&) {
        std::fprintf(stderr,
                     "fourierflare: warning: %s is deprecated: use %s (the old spelling goes in the next release)\n",
                     old.c_str(), now.c_str());
    });
}

/// An option that no longer has an effect, accepted for one release with a warning saying why (not
/// hidden by --quiet). Its value is read and ignored. Hidden from the help.
inline CLI::Option* addRetired(CLI::App& cmd, const std::string& old, const std::string& why) {
    return cmd.add_option(old)->group("")->each([old, why](const std::string&) {
        std::fprintf(stderr, "fourierflare: warning: %s no longer has an effect (%s); it goes in the next release\n",
                     old.c_str(), why.c_str());
    });
}

} // namespace ff::cli
