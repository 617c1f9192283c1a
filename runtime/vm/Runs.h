// Runs: the serialised form's encoding of long sequences (format 7), so that a model's repeated
// structure costs its bytes once, not once per element (issue 15). A chain of 10⁶ masses has 2·10⁶
// variable names `x[1]` … `der(x[1000000])`, 8·10⁶ Jacobian row indices and as many CSC positions
// in its loops' index table; written one by one they made a 150 MB executable (20 s to build).
//
// Words: a sequence of u32 values is the total count N, then runs until N values are produced:
//   count c ≥ 2, period p ≤ kMaxPeriod (32), then p pairs (base, stride):
//       the c·p values v[t·p + k] = base_k + t·stride_k (mod 2³²), t < c, k < p
//   count 0, length L ≥ 1, then L values as they are (a literal block).
// The chain's row indices, column after column (j−1, j, j+1, n+j), are one run of period 4.
//
// Strings: each string is its decimal numbers written without a leading zero (9 digits at most,
// so each fits a u32) and the text around them, its template (`links[12].s0` → "links[" 12 "].s" 0
// ""): a table of the distinct templates, then each string's template and all numbers in order as
// two word sequences. `x[1]` … `x[n]` is one template and two runs; so are a component array's
// parameters `links[i].k`, `links[i].c`, `links[i].s0` (period 3, and 4 numbers per period).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace qdot::bc::runs {

/// Long enough for the code of one element of a straight-line program (a component array's
/// parameter binding is 5 instructions, 16 words).
inline constexpr uint32_t kMaxPeriod = 32;
/// More values than this in one sequence is malformed (a guard against absurd counts: 512 MiB).
inline constexpr uint32_t kMaxValues = 1u << 27;

/// Appends the words encoding `values` to `out`.
void encodeWords(std::span<const uint32_t> values, std::vector<uint32_t>& out);

/// Where encoded words are read from: `next()` returns false when none is left.
class WordSource {
 public:
  virtual ~WordSource() = default;
  virtual bool next(uint32_t& word) = 0;
};

/// Decodes one sequence; false (and `values` unspecified) if the words are malformed.
bool decodeWords(WordSource& in, std::vector<uint32_t>& values);

/// Strings as templates and numbers (above): the template table and the two sequences.
struct StringTemplates {
  /// The text before, between and after a string's numbers: one part more than it has numbers.
  using Template = std::vector<std::string>;
  std::vector<Template> templates;
  std::vector<uint32_t> templateOf, numbers;
};
StringTemplates splitStrings(std::span<const std::string> strings);
/// The strings back; false if a template index is out of range or the numbers do not fill the
/// templates exactly.
bool joinStrings(const StringTemplates& t, std::vector<std::string>& strings);

}  // namespace qdot::bc::runs
