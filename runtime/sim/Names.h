// Command-line mistakes about names: UsageError (the caller exits with code 2) and the
// "did you mean" suggestion for an unknown parameter or column name (edit distance).
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace qdot::rt {

/// A bad command line or option value; the message is one complete sentence.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Edit distance counting insertions, deletions, substitutions and swaps of neighbours
/// (optimal string alignment), so "omgea" is 1 away from "omega".
std::size_t editDistance(std::string_view a, std::string_view b);

/// The candidate nearest to name if it is close enough to be a likely typo (distance at most
/// max(1, |name| / 3)), else nullopt. Ties go to the first candidate.
std::optional<std::string_view> closestName(std::string_view name, std::span<const std::string_view> candidates);

/// "unknown parameter 'mas' (did you mean 'mass'?)" or "unknown parameter 'q'; the model has: a, b".
std::string unknownNameMessage(std::string_view what, std::string_view name,
                               std::span<const std::string_view> candidates);

}  // namespace qdot::rt
