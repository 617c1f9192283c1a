// Loops of qdot's register programs (kernel IR and bytecode alike): a `loop` … `endloop` pair runs
// its body `count` times; iteration c has the loop offset L that the looped opcodes of
// qdot/opcodes.def add to their immediate (ldyl: y[I + L], stl: out[I + L]). The offsets are an
// arithmetic sequence or a slice of the program's index table (an irregular index set).
#ifndef QDOT_LOOP_HPP
#define QDOT_LOOP_HPP

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>

namespace qdot {

/// A loop of a program: iterations c = 0 .. count-1; at iteration c the loop offset L is
/// first + c*stride if offsetTable == kNoTable, else indexTable[offsetTable + c].
struct Loop {
  static constexpr uint32_t kNoTable = UINT32_MAX;
  uint32_t count = 0;
  int32_t first = 0, stride = 1;
  uint32_t offsetTable = kNoTable;

  /// L at iteration c (`table`: the program's index table; the slice must be inside it).
  int64_t offset(uint32_t c, const uint32_t* table) const {
    if (offsetTable == kNoTable) return int64_t{first} + int64_t{c} * stride;
    return table[offsetTable + c];
  }
};

/// The smallest and largest offset of a loop with count > 0.
struct OffsetRange {
  int64_t min = 0, max = 0;
};

/// The offsets loop `l` takes; false if count is 0 or its table slice is not inside `table`.
inline bool offsetRange(const Loop& l, std::span<const uint32_t> table, OffsetRange& range) {
  if (l.count == 0) return false;
  if (l.offsetTable == Loop::kNoTable) {
    int64_t last = l.offset(l.count - 1, nullptr);
    range = {std::min<int64_t>(l.first, last), std::max<int64_t>(l.first, last)};
    return true;
  }
  if (l.offsetTable > table.size() || table.size() - l.offsetTable < l.count) return false;
  auto slice = table.subspan(l.offsetTable, l.count);
  auto [lo, hi] = std::minmax_element(slice.begin(), slice.end());
  range = {*lo, *hi};
  return true;
}

/// "count 98, L = 1 + 2*c" or "count 98, L = X[5 + c]" (the printers of both IRs).
inline std::string loopText(const Loop& l) {
  std::string s = "count " + std::to_string(l.count) + ", L = ";
  if (l.offsetTable != Loop::kNoTable) return s + "X[" + std::to_string(l.offsetTable) + " + c]";
  return s + std::to_string(l.first) + " + " + std::to_string(l.stride) + "*c";
}

}  // namespace qdot

#endif  // QDOT_LOOP_HPP
