// UnknownSymbols: which unknown of a DAE a symbol is (variable j's y or y'), by symbol id. Built once
// per module and shared by differentiation, the template blocks' element checks and every program's
// loads: a large model has millions of y and y', and a table per use (or a hash map) cost the kernel
// stage more than its loops did.
#pragma once

#include <optional>
#include <vector>

#include "dae/Dae.h"

namespace qdot::kernel {

class UnknownSymbols {
 public:
  struct Unknown {
    uint32_t variable;
    bool derivative;  ///< y' (else y)
  };

  /// Every variable's y and y'. A symbol listed twice is the last variable naming it.
  explicit UnknownSymbols(const dae::Dae& dae) {
    for (uint32_t j = 0; j < dae.variables.size(); ++j) {
      add(dae.variables[j].y, j, false);
      if (dae.variables[j].yp) add(dae.variables[j].yp, j, true);
    }
  }

  /// The unknown `symbol` is, or nullopt.
  std::optional<Unknown> find(sym::Expr symbol) const {
    uint32_t code = symbol->symbolId < codes_.size() ? codes_[symbol->symbolId] : kNone;
    if (code == kNone) return std::nullopt;
    return Unknown{code >> 1, (code & 1) != 0};
  }

 private:
  static constexpr uint32_t kNone = UINT32_MAX;
  void add(sym::Expr symbol, uint32_t variable, bool derivative) {
    if (codes_.size() <= symbol->symbolId) codes_.resize(symbol->symbolId + 1, kNone);
    codes_[symbol->symbolId] = variable << 1 | (derivative ? 1u : 0u);
  }
  std::vector<uint32_t> codes_;  // by symbol id: 2·variable + (1 for y'), kNone: not an unknown
};

}  // namespace qdot::kernel
