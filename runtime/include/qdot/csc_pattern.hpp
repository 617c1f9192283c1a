// Whether a CSC sparsity pattern is well formed, in one tight pass: column starts from 0 to the
// number of nonzeros, never decreasing, and in each column row indices in [0, rows) and strictly
// ascending. Backends and the runtime check every compiled model's pattern before they use it; at
// 10⁶ unknowns (6·10⁶ nonzeros) a loop that stops at the first problem, column by column, cost
// 20 ms per check. This one accumulates a flag without branching on each entry; callers that
// find the pattern invalid walk it again for the message.
#pragma once

#include <cstddef>
#include <cstdint>

#include "qdot/two_halves.hpp"

namespace qdot {

template <class Start, class Row>
bool cscPatternValid(const Start* starts, const Row* rowIndices, size_t columns, size_t nonzeros, size_t rows) {
  if (starts[0] != 0 || static_cast<size_t>(starts[columns]) != nonzeros) return false;
  bool ok[2] = {true, true};  // per half of the columns (two threads from 65 536 columns)
  inTwoHalves(columns, [&](size_t first, size_t last) {
    bool& good = ok[first == 0 ? 0 : 1];
    for (size_t j = first; j < last; ++j) {
      Start begin = starts[j], end = starts[j + 1];
      if (begin > end || end > static_cast<Start>(nonzeros)) {
        good = false;
        return;
      }
      if (begin == end) continue;
      good &= (rowIndices[begin] >= 0) & (static_cast<size_t>(rowIndices[begin]) < rows);
      // after a first row in range, ascending rows are non-negative: only the upper bound is left
      for (Start k = begin + 1; k < end; ++k)
        good &= (rowIndices[k] > rowIndices[k - 1]) & (static_cast<size_t>(rowIndices[k]) < rows);
    }
  });
  return ok[0] && ok[1];
}

}  // namespace qdot
