// Edit distance and the suggestion text for unknown names on the command line.
#include "sim/Names.h"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

namespace qdot::rt {

std::size_t editDistance(std::string_view a, std::string_view b) {
  // Optimal string alignment: three rows of the dynamic programme (two back for transpositions).
  std::vector<std::size_t> before(b.size() + 1), previous(b.size() + 1), current(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    previous[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        current[j] = std::min(current[j], before[j - 2] + 1);
    }
    std::swap(before, previous);
    std::swap(previous, current);
  }
  return previous[b.size()];
}

std::optional<std::string_view> closestName(std::string_view name, std::span<const std::string_view> candidates) {
  std::optional<std::string_view> best;
  std::size_t bestDistance = std::max<std::size_t>(1, name.size() / 3) + 1;
  for (std::string_view candidate : candidates) {
    std::size_t d = editDistance(name, candidate);
    if (d < bestDistance) {
      best = candidate;
      bestDistance = d;
    }
  }
  return best;
}

std::string unknownNameMessage(std::string_view what, std::string_view name,
                               std::span<const std::string_view> candidates) {
  if (auto suggestion = closestName(name, candidates))
    return fmt::format("unknown {} '{}' (did you mean '{}'?)", what, name, *suggestion);
  if (candidates.empty()) return fmt::format("unknown {} '{}': the model has none", what, name);
  constexpr std::size_t kListed = 12;
  std::size_t listed = std::min(candidates.size(), kListed);
  std::string list = fmt::format("{}", fmt::join(candidates.begin(), candidates.begin() + listed, ", "));
  if (listed < candidates.size()) list += fmt::format(", ... ({} in all)", candidates.size());
  return fmt::format("unknown {} '{}'; the model has: {}", what, name, list);
}

}  // namespace qdot::rt
