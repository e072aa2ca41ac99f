#pragma once
// Strict text handling for the input parsers: tokens that remember their 1-based column, number
// parsing that rejects trailing junk, NaN and overflow (never atof), and "did you mean" suggestions.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace ff::text {

struct Token {
    std::string_view text;
    int column = 0; ///< 1-based column of the token's first character in its line
};

/// Splits a line on spaces/tabs into tokens, stopping at a token that starts with '#' (a comment).
/// A '#' inside a token ("Lens#2") is part of it.
std::vector<Token> tokenize(std::string_view line);

/// Parses a finite decimal number ("1.5", "-2e-3", "+4"). Rejects empty strings, trailing
/// characters, "nan", "inf" and values that overflow a double. Returns nullopt on failure.
std::optional<double> parseNumber(std::string_view s);

/// Parses a non-negative decimal integer that fits in an int.
std::optional<int> parseInt(std::string_view s);

std::string_view trim(std::string_view s);
std::string toLower(std::string_view s);
std::string toUpper(std::string_view s);
bool iequals(std::string_view a, std::string_view b);
bool startsWith(std::string_view s, std::string_view prefix);

/// Splits s on a single separator character, keeping empty fields.
std::vector<std::string_view> split(std::string_view s, char sep);

/// Renders a token for an error message: quoted and shortened if very long, escaped as printable().
std::string quoted(std::string_view s);

/// s with every byte that is not part of valid UTF-8, and every control character but newline and
/// tab, written as \xNN: what a message may carry from a file's bytes to a terminal or a log.
std::string printable(std::string_view s);

/// Edit distance (insertions, deletions, substitutions), case-insensitive.
std::size_t editDistance(std::string_view a, std::string_view b);

/// Up to maxCount candidates that are close to name: containing it (or contained in it), or within
/// a small edit distance, compared on lower-case letters and digits only; best first.
std::vector<std::string> closestNames(std::string_view name, const std::vector<std::string>& candidates,
                                      std::size_t maxCount = 3);

/// "did you mean A, B or C?" from closestNames, or "valid <what>: <all candidates>" when none is close.
std::string suggestion(std::string_view name, const std::vector<std::string>& candidates, std::string_view what);

/// "a, b, c" joined with a separator.
std::string join(const std::vector<std::string>& items, std::string_view sep = ", ");

/// Formats a number with a fixed number of decimals ("%.*f").
std::string fixed(double v, int decimals);
/// Formats a number in scientific notation with `decimals` digits after the point ("%.*e").
std::string scientific(double v, int decimals);

/// Shortest representation that reads back to exactly the same double.
std::string roundTrip(double v);

} // namespace ff::text
