#include "core/text.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

namespace ff::text {

std::vector<Token> tokenize(std::string_view line) {
    std::vector<Token> tokens;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
        if (i >= line.size() || line[i] == '#') break;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
        tokens.push_back({line.substr(start, i - start), static_cast<int>(start) + 1});
    }
    return tokens;
}

std::optional<double> parseNumber(std::string_view s) {
    if (s.empty()) return std::nullopt;
    if (s.front() == '+') {
        s.remove_prefix(1);
        if (s.empty() || s.front() == '-' || s.front() == '+') return std::nullopt;
    }
    // from_chars also accepts "inf", "nan" and hex floats only with the hex format flag; reject the
    // named specials explicitly so only plain decimal numbers pass.
    for (char c : s)
        if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == 'e' || c == 'E' || c == '+'))
            return std::nullopt;
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
    if (ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

std::optional<int> parseInt(std::string_view s) {
    if (s.empty()) return std::nullopt;
    int v = 0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || ptr != s.data() + s.size() || v < 0) return std::nullopt;
    return v;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
}

std::string toLower(std::string_view s) {
    std::string r(s);
    for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return r;
}

std::string toUpper(std::string_view s) {
    std::string r(s);
    for (char& c : r) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return r;
}

bool iequals(std::string_view a, std::string_view b) {
    return a.size() == b.size() && toLower(a) == toLower(b);
}

bool startsWith(std::string_view s, std::string_view prefix) {
    return s.substr(0, prefix.size()) == prefix;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> parts;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= s.size(); ++i) {
        if (i == s.size() || s[i] == sep) {
            parts.push_back(s.substr(start, i - start));
            start = i + 1;
        }
    }
    return parts;
}

namespace {

// Length of the valid UTF-8 sequence starting at s[i] (1 to 4), or 0 if it is not one (RFC 3629:
// no overlong forms, no surrogates, nothing beyond U+10FFFF).
std::size_t utf8Length(std::string_view s, std::size_t i) {
    const auto at = [&](std::size_t k) { return k < s.size() ? static_cast<unsigned char>(s[k]) : 0u; };
    const unsigned c = at(i);
    if (c < 0x80) return 1;
    std::size_t n = 0;
    unsigned lo = 0x80, hi = 0xbf; // the allowed range of the second byte
    if (c >= 0xc2 && c <= 0xdf)
        n = 2;
    else if (c >= 0xe0 && c <= 0xef) {
        n = 3;
        if (c == 0xe0) lo = 0xa0;
        if (c == 0xed) hi = 0x9f;
    } else if (c >= 0xf0 && c <= 0xf4) {
        n = 4;
        if (c == 0xf0) lo = 0x90;
        if (c == 0xf4) hi = 0x8f;
    } else
        return 0;
    if (at(i + 1) < lo || at(i + 1) > hi) return 0;
    for (std::size_t k = 2; k < n; ++k)
        if (at(i + k) < 0x80 || at(i + k) > 0xbf) return 0;
    return n;
}

std::string escaped(std::string_view s, bool keepLineBreaks) {
    std::string r;
    r.reserve(s.size());
    for (std::size_t i = 0; i < s.size();) {
        const auto c = static_cast<unsigned char>(s[i]);
        const std::size_t n = utf8Length(s, i);
        if (n == 0 || (n == 1 && (c < 0x20 || c == 0x7f) && !(keepLineBreaks && (c == '\n' || c == '\t')))) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02x", c);
            r += buf;
            ++i;
        } else {
            r.append(s.substr(i, n));
            i += n;
        }
    }
    return r;
}

} // namespace

std::string printable(std::string_view s) {
    return escaped(s, true);
}

std::string quoted(std::string_view s) {
    constexpr std::size_t kMax = 40;
    std::string r = "'";
    // Cut at kMax bytes, but not inside a UTF-8 sequence.
    std::size_t cut = 0;
    while (cut < s.size() && cut < kMax) cut += std::max<std::size_t>(1, utf8Length(s, cut));
    r += escaped(s.substr(0, std::min(cut, s.size())), false);
    if (s.size() > cut) r += "...";
    return r + "'";
}

std::size_t editDistance(std::string_view a, std::string_view b) {
    const std::string la = toLower(a), lb = toLower(b);
    std::vector<std::size_t> prev(lb.size() + 1), cur(lb.size() + 1);
    for (std::size_t j = 0; j <= lb.size(); ++j) prev[j] = j;
    for (std::size_t i = 1; i <= la.size(); ++i) {
        cur[0] = i;
        for (std::size_t j = 1; j <= lb.size(); ++j) {
            const std::size_t sub = prev[j - 1] + (la[i - 1] == lb[j - 1] ? 0 : 1);
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
        }
        std::swap(prev, cur);
    }
    return prev[lb.size()];
}

namespace {

// Lower-case letters and digits only: "N-BK7" and "nbk7" compare equal.
std::string normalizedName(std::string_view s) {
    std::string r;
    for (char c : s)
        if (std::isalnum(static_cast<unsigned char>(c)))
            r += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return r;
}

} // namespace

std::vector<std::string> closestNames(std::string_view name, const std::vector<std::string>& candidates,
                                      std::size_t maxCount) {
    // Score: 0 when one normalised name contains the other ("focal" in "focal_length"), otherwise
    // the edit distance of the normalised names; only scores up to max(2, |name| / 3) count as close.
    const std::string query = normalizedName(name);
    const std::size_t limit = std::max<std::size_t>(2, query.size() / 3);
    std::vector<std::pair<std::size_t, std::string>> scored;
    for (const auto& c : candidates) {
        const std::string cand = normalizedName(c);
        const bool contains =
            !query.empty() && (cand.find(query) != std::string::npos || query.find(cand) != std::string::npos);
        const std::size_t score = contains ? 0 : editDistance(query, cand);
        if (score <= limit) scored.emplace_back(score, c);
    }
    std::sort(scored.begin(), scored.end());
    std::vector<std::string> out;
    for (std::size_t i = 0; i < scored.size() && i < maxCount; ++i) out.push_back(scored[i].second);
    return out;
}

std::string suggestion(std::string_view name, const std::vector<std::string>& candidates, std::string_view what) {
    const auto close = closestNames(name, candidates);
    if (close.empty()) return "valid " + std::string(what) + ": " + join(candidates);
    std::string s = "did you mean ";
    for (std::size_t i = 0; i < close.size(); ++i) {
        if (i) s += (i + 1 == close.size()) ? " or " : ", ";
        s += close[i];
    }
    return s + "?";
}

std::string join(const std::vector<std::string>& items, std::string_view sep) {
    std::string r;
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (i) r += sep;
        r += items[i];
    }
    return r;
}

std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

std::string scientific(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*e", decimals, v);
    return buf;
}

std::string roundTrip(double v) {
    char buf[64];
    const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
    return ec == std::errc() ? std::string(buf, ptr) : fixed(v, 17);
}

} // namespace ff::text
