// Small string helpers shared by the layers: "did you mean" suggestions.
#pragma once

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

}  // namespace refray
