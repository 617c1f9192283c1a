// Lowering of DAG nodes to kernel instructions. Sums and products are chained in the order the
// symbolic evaluator uses (constant first, then terms/factors in canonical order), so the kernel
// rounds like sym::evaluate except where noted: divisions replace multiplications by a reciprocal,
// small integer powers use repeated multiplication (`powi`), x^2 is x*x and x^0.5 is sqrt(x).
#include "kernel/Lowering.h"

#include <bit>
#include <cmath>
#include <limits>

#include "support/Assert.h"

namespace qdot::kernel {
namespace {

// Exponents up to this magnitude use powi (repeated squaring); larger ones use pow.
constexpr double kMaxPowi = 16;

bool isSmallInteger(double e) { return e == std::trunc(e) && std::fabs(e) <= kMaxPowi; }

}  // namespace

Op opcodeOf(sym::Kind k) {
  using sym::Kind;
  switch (k) {
    case Kind::Constant:
    case Kind::Symbol:
    case Kind::Add:
    case Kind::Mul:
    case Kind::Pow: return Op::Ret;
    case Kind::Sin: return Op::Sin;
    case Kind::Cos: return Op::Cos;
    case Kind::Tan: return Op::Tan;
    case Kind::Asin: return Op::Asin;
    case Kind::Acos: return Op::Acos;
    case Kind::Atan: return Op::Atan;
    case Kind::Sinh: return Op::Sinh;
    case Kind::Cosh: return Op::Cosh;
    case Kind::Tanh: return Op::Tanh;
    case Kind::Exp: return Op::Exp;
    case Kind::Log: return Op::Log;
    case Kind::Abs: return Op::Abs;
    case Kind::Sign: return Op::Sign;
    case Kind::Atan2: return Op::Atan2;
    case Kind::Min: return Op::Min;
    case Kind::Max: return Op::Max;
    case Kind::Lt: return Op::Lt;
    case Kind::Le: return Op::Le;
    case Kind::Eq: return Op::Eq;
    case Kind::Ne: return Op::Ne;
    case Kind::And: return Op::And;
    case Kind::Or: return Op::Or;
    case Kind::Not: return Op::Not;
    case Kind::Select: return Op::Select;
  }
  return Op::Ret;
}

uint32_t ProgramBuilder::emit(Op op, uint32_t a, uint32_t b, uint32_t c, uint32_t imm) {
  program_.code.push_back({op, a, b, c, imm, source_});
  return static_cast<uint32_t>(program_.code.size() - 1);
}

// The pool key of v: -0 is 0, every NaN is the quiet NaN.
uint64_t ProgramBuilder::constantBits(double v) {
  if (std::isnan(v)) return std::bit_cast<uint64_t>(std::numeric_limits<double>::quiet_NaN());
  return std::bit_cast<uint64_t>(v == 0.0 ? 0.0 : v);
}

uint32_t ProgramBuilder::constant(double v) {
  uint64_t bits = constantBits(v);
  if (const uint32_t* r = knownConstant(bits)) return *r;
  auto [index, fresh] = pool_.insert(bits, static_cast<uint32_t>(program_.constants.size()));
  if (fresh) program_.constants.push_back(std::bit_cast<double>(bits));
  uint32_t r = emit(Op::LoadConst, 0, 0, 0, index);
  (inLoop_ ? bodyConstants_ : constants_).insert(bits, r);
  return r;
}

// The register of a constant's `ldk` (outside loops the body's map is empty).
const uint32_t* ProgramBuilder::knownConstant(uint64_t bits) const {
  if (const uint32_t* r = constants_.find(bits)) return r;
  return bodyConstants_.find(bits);
}

// Symbols by id, constants by value (one `ldk` per bit pattern and scope), other nodes in the memo.
const uint32_t* ProgramBuilder::known(sym::Expr e) const {
  if (e->isConstant()) return knownConstant(constantBits(e->value));
  if (!e->isSymbol()) {
    const uint32_t* r = memo_.find(e);
    return r ? r : bodyMemo_.find(e);
  }
  const uint32_t* r = symbolRegs_.find(e->symbolId);
  return r && *r != kNone ? r : nullptr;
}

void ProgramBuilder::remember(sym::Expr e, uint32_t reg) {
  if (e->isConstant()) return;  // constant() keeps it
  if (e->isSymbol()) setSymbolRegister(e, reg);
  else (inLoop_ ? bodyMemo_ : memo_).insert(e, reg);
}

void ProgramBuilder::setSymbolRegister(sym::Expr symbol, uint32_t reg) {
  uint32_t& r = symbolRegs_.at(symbol->symbolId);
  if (inLoop_) bodySymbols_.emplace_back(symbol->symbolId, r);
  r = reg;
}

uint32_t ProgramBuilder::beginLoop(const Loop& loop) {
  QDOT_ASSERT(!inLoop_, "loops do not nest");
  auto id = static_cast<uint32_t>(program_.loops.size());
  program_.loops.push_back(loop);
  emit(Op::LoopBegin, 0, 0, 0, id);
  inLoop_ = true;
  return id;
}

void ProgramBuilder::endLoop() {
  QDOT_ASSERT(inLoop_, "endLoop without beginLoop");
  emit(Op::LoopEnd, 0, 0, 0, static_cast<uint32_t>(program_.loops.size() - 1));
  inLoop_ = false;
  for (auto it = bodySymbols_.rbegin(); it != bodySymbols_.rend(); ++it) symbolRegs_.at(it->first) = it->second;
  bodySymbols_.clear();
  bodyMemo_.clear();
  bodyConstants_.clear();
}

uint32_t ProgramBuilder::appendIndexTable(std::span<const uint32_t> values) {
  auto base = static_cast<uint32_t>(program_.indexTable.size());
  program_.indexTable.insert(program_.indexTable.end(), values.begin(), values.end());
  return base;
}

// The next child of f.node that needs a register (arguments, non-constant exponents, a
// temporary's value), or nullptr when there is none left.
sym::Expr ProgramBuilder::nextChild(Frame& f) const {
  sym::Expr e = f.node;
  if (e->isSymbol()) return f.next++ == 0 ? temporaries_.get(e->symbolId) : nullptr;
  while (f.next < e->args.size() + e->exps().size()) {
    size_t i = f.next++;
    sym::Expr c = e->args.data()[i];  // args, then exps (one array)
    bool exponent = e->kind == sym::Kind::Pow ? i == 1 : i >= e->args.size();
    if (!exponent || !c->isConstant()) return c;
  }
  return nullptr;
}

// Post-order: children first to last, each finished before the next is looked at.
uint32_t ProgramBuilder::lower(sym::Expr root) {
  if (const uint32_t* r = known(root)) return *r;
  frames_.assign(1, {root, 0});
  while (!frames_.empty()) {
    Frame& f = frames_.back();
    if (sym::Expr c = nextChild(f)) {
      if (!known(c)) frames_.push_back({c, 0});
      continue;
    }
    sym::Expr e = f.node;
    frames_.pop_back();
    uint32_t r = emitNode(e);
    remember(e, r);
  }
  return reg(root);
}

uint32_t ProgramBuilder::emitNode(sym::Expr e) {
  switch (e->kind) {
    case sym::Kind::Constant: return constant(e->value);
    case sym::Kind::Symbol: return emitSymbol(e);
    case sym::Kind::Add: return emitAdd(e);
    case sym::Kind::Mul: return emitMul(e);
    case sym::Kind::Pow: return emitPow(e);
    default: break;
  }
  uint32_t a = reg(e->args[0]);
  uint32_t b = e->args.size() > 1 ? reg(e->args[1]) : 0;
  uint32_t c = e->args.size() > 2 ? reg(e->args[2]) : 0;
  return emit(opcodeOf(e->kind), a, b, c);
}

uint32_t ProgramBuilder::emitSymbol(sym::Expr e) {
  if (sym::Expr t = temporaries_.get(e->symbolId)) return reg(t);
  if (Load l = loads_.get(e->symbolId); l.second != kNone) return emit(l.first, 0, 0, 0, l.second);
  if (auto u = unknowns_ ? unknowns_->find(e) : std::nullopt)
    return emit(u->derivative ? Op::LoadYp : Op::LoadY, 0, 0, 0, u->variable);
  unbound_.push_back({e, source_});
  return constant(std::numeric_limits<double>::quiet_NaN());
}

// c + k0*x0 + k1*x1 + ...: accumulated left to right; k = 1 adds, k = -1 subtracts.
uint32_t ProgramBuilder::emitAdd(sym::Expr e) {
  uint32_t acc = kNone;
  size_t j = 0, n = e->args.size();
  auto term = [&](size_t i) {
    double k = e->coefs()[i];
    uint32_t x = reg(e->args[i]);
    return k == 1.0 ? x : k == -1.0 ? emit(Op::Neg, x) : emit(Op::Mul, constant(k), x);
  };
  if (e->value != 0.0) {
    acc = constant(e->value);
  } else if (n >= 2 && e->coefs()[0] == -1.0) {  // -x0 + k1*x1 == k1*x1 - x0 exactly
    acc = emit(Op::Sub, term(1), reg(e->args[0]));
    j = 2;
  }
  for (; j < n; ++j) {
    double k = e->coefs()[j];
    if (acc == kNone) acc = term(j);
    else if (k == -1.0) acc = emit(Op::Sub, acc, reg(e->args[j]));
    else acc = emit(Op::Add, acc, term(j));
  }
  return acc;
}

// k * Π b^e: the coefficient and the factors with non-negative (or symbolic) exponents multiply
// left to right, then the factors with negative constant exponents divide.
uint32_t ProgramBuilder::emitMul(sym::Expr e) {
  double k = e->value;
  uint32_t acc = k == 1.0 || k == -1.0 ? kNone : constant(k);
  size_t n = e->args.size();
  for (size_t j = 0; j < n; ++j) {
    sym::Expr x = e->exps()[j];
    if (x->isConstant() && x->value < 0) continue;
    uint32_t f = x->isConstant() ? power(reg(e->args[j]), x->value) : emit(Op::Pow, reg(e->args[j]), reg(x));
    acc = acc == kNone ? f : emit(Op::Mul, acc, f);
  }
  for (size_t j = 0; j < n; ++j) {
    sym::Expr x = e->exps()[j];
    if (!x->isConstant() || x->value >= 0) continue;
    uint32_t g = power(reg(e->args[j]), -x->value);
    acc = emit(Op::Div, acc == kNone ? constant(1.0) : acc, g);
  }
  return k == -1.0 ? emit(Op::Neg, acc) : acc;
}

uint32_t ProgramBuilder::emitPow(sym::Expr e) {
  uint32_t base = reg(e->args[0]);
  sym::Expr x = e->args[1];
  if (!x->isConstant()) return emit(Op::Pow, base, reg(x));
  double v = x->value;
  if (v == -1.0 || v == -0.5 || v == -2.0) {
    uint32_t one = constant(1.0);  // sequenced: the order of emission must not depend on the compiler
    return emit(Op::Div, one, power(base, -v));
  }
  return power(base, v);
}

// base^v for a constant v: x, x*x, sqrt(x), powi for small integers, else pow.
uint32_t ProgramBuilder::power(uint32_t base, double v) {
  if (v == 1.0) return base;
  if (v == 2.0) return emit(Op::Mul, base, base);
  if (v == 0.5) return emit(Op::Sqrt, base);
  if (v == 0.0) return constant(1.0);
  if (isSmallInteger(v)) return emit(Op::Powi, base, 0, 0, static_cast<uint32_t>(static_cast<int32_t>(v)));
  return emit(Op::Pow, base, constant(v));
}

Program ProgramBuilder::finish(uint32_t outputCount) {
  program_.outputCount = outputCount;
  hoistLoopConstants(program_);
  return std::move(program_);
}

}  // namespace qdot::kernel
