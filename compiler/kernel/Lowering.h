// ProgramBuilder: lowers expression DAGs into one kernel Program. Each distinct node becomes at
// most one instruction (memoised), inputs are loaded on first use, CSE temporaries are lowered on
// first use, n-ary sums and products become chains of binary operations. Iterative, so any
// expression depth is fine.
#pragma once

#include <unordered_map>

#include "kernel/Kernel.h"

namespace qdot::kernel {

class ProgramBuilder {
 public:
  static constexpr uint32_t kNone = UINT32_MAX;

  explicit ProgramBuilder(std::string name) { program_.name = std::move(name); }

  /// `symbol` reads input `index` with a load opcode (emitted when first used).
  void bindLoad(sym::Expr symbol, Op load, uint32_t index) { loads_[symbol] = {load, index}; }
  /// `symbol` is the value already in register `reg`.
  void bindRegister(sym::Expr symbol, uint32_t reg) { memo_[symbol] = reg; }
  /// `symbol` is a CSE temporary standing for `value` (lowered when first used).
  void bindTemporary(sym::Expr symbol, sym::Expr value) { temporaries_[symbol] = value; }

  /// Instructions emitted from now on serve source `s`.
  void setSource(uint32_t s) { source_ = s; }
  /// The register holding e (emitting what is not computed yet).
  uint32_t lower(sym::Expr e);
  /// The register holding constant v (one `ldk` per distinct bit pattern).
  uint32_t constant(double v);
  /// Appends an instruction and returns the register it defines.
  uint32_t emit(Op op, uint32_t a = 0, uint32_t b = 0, uint32_t c = 0, uint32_t imm = 0);
  /// out[slot] = register reg.
  void store(uint32_t slot, uint32_t reg) { emit(Op::Store, reg, 0, 0, slot); }

  /// Symbols met that have no binding (each lowered as NaN), in order of first use.
  const std::vector<sym::Expr>& unboundSymbols() const { return unbound_; }
  Program finish(uint32_t outputCount);

 private:
  void pushChildren(sym::Expr e, std::vector<std::pair<sym::Expr, bool>>& stack);
  uint32_t emitNode(sym::Expr e);
  uint32_t emitSymbol(sym::Expr e);
  uint32_t emitAdd(sym::Expr e);
  uint32_t emitMul(sym::Expr e);
  uint32_t emitPow(sym::Expr e);
  uint32_t power(uint32_t base, double exponent);
  uint32_t reg(sym::Expr e) const { return memo_.at(e); }

  Program program_;
  uint32_t source_ = UINT32_MAX;
  std::unordered_map<sym::Expr, uint32_t> memo_;
  std::unordered_map<sym::Expr, std::pair<Op, uint32_t>> loads_;
  std::unordered_map<sym::Expr, sym::Expr> temporaries_;
  std::unordered_map<uint64_t, uint32_t> constants_;  // bit pattern -> register
  std::vector<sym::Expr> unbound_;
};

/// The opcode of a function kind (Sin … Select); Ret for kinds that are not functions.
Op opcodeOf(sym::Kind k);

}  // namespace qdot::kernel
