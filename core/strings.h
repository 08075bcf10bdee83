// Small string helpers shared by the layers: "did you mean" suggestions.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace refray {

size_t editDistance(std::string_view a, std::string_view b);

// The candidate closest to `name` by edit distance, if it is close enough to be a
// plausible typo (distance <= max(2, |name|/3)); comparison ignores case.
std::optional<std::string> closestMatch(std::string_view name, const std::vector<std::string>& candidates);

// " (did you mean 'X'?)" or "" — ready to append to a message.
std::string didYouMean(std::string_view name, const std::vector<std::string>& candidates);

// "a, b, c".
std::string joined(const std::vector<std::string>& names, std::string_view separator = ", ");

// "'text'": how messages and tables quote names.
std::string inQuotes(std::string_view text);
// "0x1F00": upper-case hex, zero-padded to at least `digits` digits.
std::string hexText(uint64_t value, int digits = 0);
// "Name" of "a::b::Name" (a demangled C++ type as scene files write it).
std::string withoutNamespace(std::string_view qualified);

// `text` as one POSIX shell word: unchanged when it has only [A-Za-z0-9_./:=,+-], else in single quotes (a quote
// inside becomes '\'').
std::string shellQuoted(std::string_view text);
// `text` with &, <, >, " and ' escaped for HTML.
std::string htmlEscape(std::string_view text);
// A float as the shortest decimal text that reads back as the same float ("0.1", "1e+30", "nan").
std::string shortestFloat(float value);

}  // namespace refray
