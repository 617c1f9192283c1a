// identifierNames: the header's names for tools that accept identifiers only (see ColumnNames.h).
#include "output/ColumnNames.h"

#include <unordered_set>

namespace qdot::rt {
namespace {

bool isIdentifierChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

bool isIdentifier(const std::string& name) {
  if (name.empty() || (name[0] >= '0' && name[0] <= '9')) return false;
  for (char c : name)
    if (!isIdentifierChar(c)) return false;
  return true;
}

// der(der(x[1])) -> der_der_x_1, M[1,2] -> M_1_2, a.b -> a_b
std::string asIdentifier(const std::string& name) {
  std::string out;
  bool replaced = false;  // the last character written stands for characters that could not be kept
  for (char c : name) {
    if (isIdentifierChar(c)) {
      out += c;
      replaced = false;
    } else if (c != ')' && c != ']' && !replaced) {
      out += '_';
      replaced = true;
    }
  }
  if (replaced && out.size() > 1) out.pop_back();  // say "hi" -> say_hi, not say_hi_
  if (out.empty() || (out[0] >= '0' && out[0] <= '9')) out.insert(out.begin(), '_');
  return out;
}

}  // namespace

std::vector<std::string> identifierNames(std::span<const std::string> names) {
  // Names that already are identifiers keep them; the others must not take one of theirs.
  std::unordered_set<std::string> taken = {"time"};
  for (const std::string& name : names)
    if (isIdentifier(name)) taken.insert(name);
  std::vector<std::string> out;
  out.reserve(names.size());
  for (const std::string& name : names) {
    if (isIdentifier(name)) {
      out.push_back(name);
      continue;
    }
    std::string base = asIdentifier(name), candidate = base;
    for (int k = 2; taken.count(candidate); ++k) candidate = base + "_" + std::to_string(k);
    taken.insert(candidate);
    out.push_back(std::move(candidate));
  }
  return out;
}

}  // namespace qdot::rt
