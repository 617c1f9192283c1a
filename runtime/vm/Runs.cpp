// Runs.h: periodic affine runs of words, strings as templates and numbers.
#include "vm/Runs.h"

#include <algorithm>
#include <charconv>
#include <string_view>
#include <unordered_map>

namespace qdot::bc::runs {
namespace {

// Whole periods of length p from i on that continue the first two affinely (v[i + t·p + k] −
// v[i + (t−1)·p + k] the same for every t); 0 if there are not two. Arithmetic is mod 2³².
size_t periodsFrom(std::span<const uint32_t> v, size_t i, uint32_t p) {
  if (i + 2 * size_t{p} > v.size()) return 0;
  size_t t = 2;
  for (; i + (t + 1) * p <= v.size(); ++t)
    for (uint32_t k = 0; k < p; ++k)
      if (v[i + t * p + k] - v[i + (t - 1) * p + k] != v[i + p + k] - v[i + k]) return t;
  return t;
}

struct Run {
  uint32_t period = 0;
  size_t periods = 0;
  size_t values() const { return period * periods; }
};

// The run from i covering most values (the shortest period on a tie; see below), or none if no
// run pays for its 2 + 2p words.
Run bestRunFrom(std::span<const uint32_t> v, size_t i) {
  Run best;
  // A run of a short period that is already long ends the search: longer periods (its multiples
  // cover about as much) would only scan it again.
  for (uint32_t p = 1; p <= kMaxPeriod && best.values() < 16 * size_t{kMaxPeriod}; ++p) {
    Run r{p, periodsFrom(v, i, p)};
    if (r.values() > best.values()) best = r;
  }
  return best.values() > 2 + 2 * size_t{best.period} ? best : Run{};
}

}  // namespace

void encodeWords(std::span<const uint32_t> values, std::vector<uint32_t>& out) {
  out.push_back(static_cast<uint32_t>(values.size()));
  std::vector<uint32_t> literal;
  auto flushLiteral = [&] {
    if (literal.empty()) return;
    out.push_back(0);
    out.push_back(static_cast<uint32_t>(literal.size()));
    out.insert(out.end(), literal.begin(), literal.end());
    literal.clear();
  };
  for (size_t i = 0; i < values.size();) {
    Run r = bestRunFrom(values, i);
    if (r.periods == 0) {
      literal.push_back(values[i++]);
      continue;
    }
    flushLiteral();
    out.push_back(static_cast<uint32_t>(r.periods));
    out.push_back(r.period);
    for (uint32_t k = 0; k < r.period; ++k) out.push_back(values[i + k]), out.push_back(values[i + r.period + k] - values[i + k]);
    i += r.values();
  }
  flushLiteral();
}

bool decodeWords(WordSource& in, std::vector<uint32_t>& values) {
  values.clear();
  uint32_t total = 0;
  if (!in.next(total) || total > kMaxValues) return false;
  values.reserve(std::min<uint32_t>(total, 1u << 16));  // grows with what the words really hold
  while (values.size() < total) {
    size_t left = total - values.size();
    uint32_t count = 0, period = 0;
    if (!in.next(count) || !in.next(period)) return false;
    if (count == 0) {  // a literal block
      if (period == 0 || period > left) return false;
      for (uint32_t k = 0; k < period; ++k) {
        uint32_t w = 0;
        if (!in.next(w)) return false;
        values.push_back(w);
      }
      continue;
    }
    if (count < 2 || period == 0 || period > kMaxPeriod || uint64_t{count} * period > left) return false;
    uint32_t base[kMaxPeriod], stride[kMaxPeriod];
    for (uint32_t k = 0; k < period; ++k)
      if (!in.next(base[k]) || !in.next(stride[k])) return false;
    for (uint32_t t = 0; t < count; ++t)
      for (uint32_t k = 0; k < period; ++k) values.push_back(base[k] + t * stride[k]);
  }
  return true;
}

namespace {

constexpr uint32_t kLargestNumber = 999999999;  // 9 digits

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// Splits s into its template (appended to `parts`, which is cleared) and its numbers.
void splitString(std::string_view s, std::vector<std::string>& parts, std::vector<uint32_t>& numbers) {
  parts.assign(1, "");
  for (size_t i = 0; i < s.size();) {
    size_t end = i;
    while (end < s.size() && isDigit(s[end])) ++end;
    size_t digits = end - i;
    if (digits == 0 || digits > 9 || (digits > 1 && s[i] == '0')) {  // text (digits included)
      parts.back().append(s.substr(i, std::max<size_t>(digits, 1)));
      i += std::max<size_t>(digits, 1);
      continue;
    }
    uint32_t number = 0;
    for (size_t k = i; k < end; ++k) number = number * 10 + static_cast<uint32_t>(s[k] - '0');
    numbers.push_back(number);
    parts.emplace_back();
    i = end;
  }
}

}  // namespace

StringTemplates splitStrings(std::span<const std::string> strings) {
  StringTemplates t;
  t.templateOf.reserve(strings.size());
  t.numbers.reserve(strings.size());
  std::unordered_map<std::string, uint32_t> ids;
  std::vector<std::string> parts;
  std::string key;
  for (const std::string& s : strings) {
    splitString(s, parts, t.numbers);
    key.clear();
    for (const std::string& part : parts) key.append(part).append(1, '\0');
    auto [it, added] = ids.try_emplace(key, static_cast<uint32_t>(t.templates.size()));
    if (added) t.templates.push_back(parts);
    t.templateOf.push_back(it->second);
  }
  return t;
}

bool joinStrings(const StringTemplates& t, std::vector<std::string>& strings) {
  strings.clear();
  strings.reserve(t.templateOf.size());
  size_t next = 0;  // in t.numbers
  for (uint32_t id : t.templateOf) {
    if (id >= t.templates.size() || t.templates[id].empty()) return false;
    const StringTemplates::Template& parts = t.templates[id];
    if (t.numbers.size() - next < parts.size() - 1) return false;
    std::string& s = strings.emplace_back();
    s.reserve(parts[0].size() + 10 * (parts.size() - 1) + parts.back().size());
    s.append(parts[0]);
    for (size_t k = 1; k < parts.size(); ++k) {
      uint32_t number = t.numbers[next++];
      if (number > kLargestNumber) return false;  // would not be read back as one number
      char digits[10];
      s.append(digits, std::to_chars(digits, digits + sizeof digits, number).ptr).append(parts[k]);
    }
  }
  return next == t.numbers.size();
}

}  // namespace qdot::bc::runs
