// ProgramBuilder: lowers expression DAGs into one kernel Program. Each distinct node becomes at
// most one instruction (memoised), inputs are loaded on first use, CSE temporaries are lowered on
// first use, n-ary sums and products become chains of binary operations. Iterative, so any
// expression depth is fine. Loops: between beginLoop and endLoop the instructions form a loop body;
// what is first lowered there is per-iteration, so the memo forgets it at endLoop.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "kernel/Kernel.h"
#include "kernel/SymbolSlots.h"
#include "kernel/Unknowns.h"
#include "symbolic/NodeMap.h"

namespace qdot::kernel {

/// Constants by bit pattern → a register or pool index: open addressing with linear probing, as
/// sym::NodeMap. A large model's start values are up to millions of distinct numbers (10⁶
/// sin(π i/(n + 1)) in a rod): std::unordered_map's node per entry made its inserts, rehashes and
/// destruction 0.9 s of the kernel stage there.
class ConstantMap {
 public:
  /// The value stored for bits, or nullptr.
  const uint32_t* find(uint64_t bits) const {
    if (slots_.empty()) return nullptr;
    for (size_t i = slotOf(bits);; i = (i + 1) & (slots_.size() - 1)) {
      if (slots_[i].value == kEmpty) return nullptr;
      if (slots_[i].bits == bits) return &slots_[i].value;
    }
  }
  /// Inserts (bits, value) unless bits is present; the stored value and whether it was inserted.
  std::pair<uint32_t, bool> insert(uint64_t bits, uint32_t value) {
    if ((size_ + 1) * 4 > slots_.size() * 3) grow();
    for (size_t i = slotOf(bits);; i = (i + 1) & (slots_.size() - 1)) {
      if (slots_[i].value == kEmpty) {
        slots_[i] = {bits, value};
        ++size_;
        return {value, true};
      }
      if (slots_[i].bits == bits) return {slots_[i].value, false};
    }
  }
  void clear() {
    if (size_ == 0) return;
    std::fill(slots_.begin(), slots_.end(), Slot{});
    size_ = 0;
  }

 private:
  static constexpr uint32_t kEmpty = UINT32_MAX;  ///< no register or pool index is this
  struct Slot {
    uint64_t bits = 0;
    uint32_t value = kEmpty;
  };
  size_t slotOf(uint64_t bits) const { return static_cast<size_t>((bits * 0x9E3779B97F4A7C15ull) >> 20) & (slots_.size() - 1); }
  void grow() {
    std::vector<Slot> old(std::max<size_t>(16, 2 * slots_.size()));
    old.swap(slots_);
    size_ = 0;
    for (const Slot& s : old)
      if (s.value != kEmpty) insert(s.bits, s.value);
  }
  std::vector<Slot> slots_;
  size_t size_ = 0;
};

class ProgramBuilder {
 public:
  static constexpr uint32_t kNone = UINT32_MAX;

  explicit ProgramBuilder(std::string name) { program_.name = std::move(name); }

  /// `symbol` reads input `index` with a load opcode (emitted when first used).
  void bindLoad(sym::Expr symbol, Op load, uint32_t index) { loads_.at(symbol->symbolId) = {load, index}; }
  /// Each unknown's y and y' read input y[j] and yp[j] (Op::LoadY, Op::LoadYp), j its variable;
  /// bindLoad wins over this. The table is shared, not copied: it must outlive the builder.
  void bindUnknowns(const UnknownSymbols& unknowns) { unknowns_ = &unknowns; }
  /// `symbol` reads y[index + L] (Op::LoadYLooped), yp[index + L] (Op::LoadYpLooped) or p[index + L]
  /// (Op::LoadPLooped) inside loops.
  void bindLoopedLoad(sym::Expr symbol, Op load, uint32_t index) { bindLoad(symbol, load, index); }
  /// `symbol` is the loop offset L as a number (ldidx).
  void bindLoopOffset(sym::Expr symbol) { bindLoad(symbol, Op::LoadLoopOffset, 0); }
  /// `symbol` is the value already in register `reg` (inside a loop body: until endLoop).
  void bindRegister(sym::Expr symbol, uint32_t reg) { setSymbolRegister(symbol, reg); }
  /// `symbol` is a CSE temporary standing for `value` (lowered when first used).
  void bindTemporary(sym::Expr symbol, sym::Expr value) { temporaries_.at(symbol->symbolId) = value; }

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

  /// Starts a loop body: instructions emitted until endLoop() run loop.count times. Returns the loop id.
  uint32_t beginLoop(const Loop& loop);
  /// Ends the body. Nodes, symbols and temporaries first lowered inside the body are forgotten (they
  /// hold per-iteration values); those lowered before stay valid inside and after.
  void endLoop();
  /// out[slot + L] = reg ; out[indexTable[tableBase + c]] = reg   (inside a loop)
  void storeLooped(uint32_t slot, uint32_t reg) { emit(Op::StoreLooped, reg, 0, 0, slot); }
  void storeIndexed(uint32_t tableBase, uint32_t reg) { emit(Op::StoreIndexed, reg, 0, 0, tableBase); }
  /// out[slot] += reg  (a sum over a loop's iterations, after out[slot] was stored)
  void storeAdd(uint32_t slot, uint32_t reg) { emit(Op::StoreAdd, reg, 0, 0, slot); }
  /// Appends to the program's indexTable; returns the base index.
  uint32_t appendIndexTable(std::span<const uint32_t> values);
  /// Room for `count` more indexTable entries (a large model appends millions).
  void reserveIndexTable(size_t count) { program_.indexTable.reserve(program_.indexTable.size() + count); }

  /// A symbol met that has no binding (lowered as NaN), and the source whose code first used it.
  struct UnboundUse {
    sym::Expr symbol;
    uint32_t source;
  };
  /// Every unbound symbol, in order of first use.
  const std::vector<UnboundUse>& unboundSymbols() const { return unbound_; }
  Program finish(uint32_t outputCount);

 private:
  // What a symbol stands for (a temporary wins over a load) and its register once known, by symbol
  // id (symbols are the most used nodes) in pages: a program of a large model reads few of its
  // millions of symbols. Separate tables: the register, looked up most, stays compact.
  using Load = std::pair<Op, uint32_t>;  // index kNone: no load
  static constexpr Load kNoLoad{Op::Ret, kNone};
  struct Frame {
    sym::Expr node;
    size_t next;  // next child to look at
  };
  sym::Expr nextChild(Frame& f) const;
  uint32_t emitNode(sym::Expr e);
  uint32_t emitSymbol(sym::Expr e);
  uint32_t emitAdd(sym::Expr e);
  uint32_t emitMul(sym::Expr e);
  uint32_t emitPow(sym::Expr e);
  uint32_t power(uint32_t base, double exponent);
  static uint64_t constantBits(double v);
  const uint32_t* known(sym::Expr e) const;
  const uint32_t* knownConstant(uint64_t bits) const;
  void remember(sym::Expr e, uint32_t reg);
  void setSymbolRegister(sym::Expr symbol, uint32_t reg);
  uint32_t reg(sym::Expr e) const { return *known(e); }

  Program program_;
  uint32_t source_ = UINT32_MAX;
  sym::NodeMap<uint32_t> memo_;                       // node (not a leaf) -> register
  SymbolSlots<uint32_t> symbolRegs_{kNone};           // kNone: not lowered yet
  SymbolSlots<sym::Expr> temporaries_{nullptr};
  SymbolSlots<Load> loads_{kNoLoad};
  const UnknownSymbols* unknowns_ = nullptr;          // loads of y and y' not in loads_
  ConstantMap constants_;  // bit pattern -> register
  ConstantMap pool_;       // bit pattern -> index in the pool
  // The open loop body's own values, forgotten at endLoop: nodes, constants, and the symbols'
  // registers it set (symbol id, register before), undone in reverse.
  bool inLoop_ = false;
  sym::NodeMap<uint32_t> bodyMemo_;
  ConstantMap bodyConstants_;
  std::vector<std::pair<uint32_t, uint32_t>> bodySymbols_;
  std::vector<UnboundUse> unbound_;
  std::vector<Frame> frames_;  // lower()'s stack, kept to reuse its storage
};

/// The opcode of a function kind (Sin … Select); Ret for kinds that are not functions.
Op opcodeOf(sym::Kind k);

}  // namespace qdot::kernel
