// Non-finite diagnosis over the kernel IR: instruction i's value is computed with the opcodes.def
// expressions (as kernel::interpret does); origin[i] is the instruction where the non-finite value
// it carries first arose from finite operands. Only the operands a result depends on count (for a
// select: the condition and the branch taken). A non-finite constant marks a value "undefined".
#include "llvm/Diagnose.h"

#include <charconv>
#include <cmath>
#include <unordered_map>

#include "qdot/bytecode.h"

namespace qdot::llvmbackend {
namespace {

using kernel::Instr;
using kernel::Op;

constexpr uint32_t kFinite = UINT32_MAX;        // origin of a finite value
constexpr uint32_t kConstant = UINT32_MAX - 1;  // a non-finite constant of the pool

const char* const kProgramNames[kernel::kProgramCount] = {"parameters", "initialValues", "residual",
                                                          "jacobian",   "outputs",       "invariants"};

// The value instruction `ins` computes (a store: the value stored).
double evaluate(const Instr& ins, const std::vector<double>& r, const kernel::Inputs& in, const double* k) {
  const double t = in.t, cj = in.cj;
  const double *y = in.y.data(), *yp = in.yp.data(), *p = in.p.data(), *given = in.given.data();
  const uint8_t* overridden = in.overridden.data();
  const double A = r[ins.a], B = r[ins.b], C = r[ins.c];
  const uint32_t I = ins.imm;
  (void)t, (void)cj, (void)y, (void)yp, (void)p, (void)given, (void)overridden, (void)C, (void)I, (void)k;
  switch (ins.op) {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) \
  case Op::Name: return (Value);
#include "qdot/opcodes.def"
  }
  return 0.0;
}

// The registers the result of `ins` depends on.
unsigned dependencies(const Instr& ins, const std::vector<double>& r, uint32_t deps[3]) {
  if (ins.op == Op::Select) {
    deps[0] = ins.a, deps[1] = r[ins.a] != 0.0 ? ins.b : ins.c;
    return 2;
  }
  switch (ins.op) {
#define QDOT_DEPS_End 0
#define QDOT_DEPS_None 0
#define QDOT_DEPS_Index 0
#define QDOT_DEPS_Unary 1
#define QDOT_DEPS_Binary 2
#define QDOT_DEPS_Ternary 3
#define QDOT_DEPS_UnaryIndex 1
#define QDOT_DEPS_Store 1
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) \
  case Op::Name:                                   \
    deps[0] = ins.a, deps[1] = ins.b, deps[2] = ins.c; \
    return QDOT_DEPS_##Format;
#include "qdot/opcodes.def"
  }
  return 0;
}

std::string num(double v) {
  char buf[32];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

std::string nameAt(const std::vector<std::string>& names, uint32_t i) { return i < names.size() ? names[i] : "?"; }

// Why `ins` produced a non-finite value from finite operands A, B (or from nothing, for loads).
std::string describeProblem(const kernel::KernelModule& m, const Instr& ins, double A, double B, double value) {
  switch (ins.op) {
    case Op::Sqrt: return "sqrt of a negative number (" + num(A) + ")";
    case Op::Log: return A == 0.0 ? "log of zero" : "log of a negative number (" + num(A) + ")";
    case Op::Asin:
    case Op::Acos: return std::string(kernel::mnemonic(ins.op)) + " of a number outside [-1, 1] (" + num(A) + ")";
    case Op::Div: return B == 0.0 ? "division by zero (" + num(A) + "/0)" : "overflow in " + num(A) + "/" + num(B);
    case Op::Pow:
      if (A < 0.0 && B != std::trunc(B)) return "power of a negative number (" + num(A) + "^" + num(B) + ")";
      return A == 0.0 ? "zero to a negative power (0^" + num(B) + ")" : "overflow in " + num(A) + "^" + num(B);
    case Op::Powi: {
      std::string e = std::to_string(static_cast<int32_t>(ins.imm));
      return A == 0.0 ? "zero to a negative power (0^" + e + ")" : "overflow in " + num(A) + "^" + e;
    }
    case Op::LoadY: return "the value of " + nameAt(m.variableNames, ins.imm) + " is " + num(value);
    case Op::LoadYp: return "the value of der(" + nameAt(m.variableNames, ins.imm) + ") is " + num(value);
    case Op::LoadP: return "parameter " + nameAt(m.parameterNames, ins.imm) + " is " + num(value);
    case Op::LoadGiven: return "the value given for parameter " + nameAt(m.parameterNames, ins.imm) + " is " + num(value);
    case Op::LoadTime: return "time is " + num(value);
    case Op::LoadCj: return "cj is " + num(value);
    default: break;
  }
  return "overflow in " + std::string(kernel::mnemonic(ins.op)) + " (" + num(value) + ")";
}

// " in <label> at <where>" of the culprit, the spoiled store's source if different, the program.
std::string placeOf(const kernel::KernelModule& m, const kernel::Program& prog, uint32_t culprit, uint32_t store,
                    kernel::ProgramId id, const std::vector<std::string>& where) {
  auto label = [&](uint32_t i) {
    uint32_t s = prog.code[i].source;
    if (s >= m.sources.size()) return std::string();
    const std::string& w = s < where.size() ? where[s] : std::string();
    return m.sources[s].label + (w.empty() ? "" : " at " + w);
  };
  std::string culpritText = label(culprit), spoiled = label(store), s;
  if (!culpritText.empty()) s = " in " + culpritText;
  if (!spoiled.empty() && spoiled != culpritText) s += ", which makes " + spoiled + " non-finite";
  if (id != kernel::ProgramId::Residual) s += std::string(" (computing ") + kProgramNames[static_cast<int>(id)] + ")";
  return s;
}

}  // namespace

std::string diagnoseNonFinite(const kernel::KernelModule& m, kernel::ProgramId id, const kernel::Inputs& in,
                              const std::vector<std::string>& where) {
  const kernel::Program& prog = m.program(id);
  std::vector<double> r(prog.code.size(), 0.0);
  std::vector<uint32_t> origin(prog.code.size(), kFinite);
  std::unordered_map<uint32_t, std::string> problems;  // culprit -> what went wrong
  for (uint32_t i = 0; i < prog.code.size(); ++i) {
    const Instr& ins = prog.code[i];
    if (ins.op == Op::Ret) break;
    uint32_t deps[3], from = kFinite;
    bool undefined = false;
    for (unsigned j = 0, n = dependencies(ins, r, deps); j < n; ++j) {
      if (std::isfinite(r[deps[j]])) continue;
      if (origin[deps[j]] == kConstant) undefined = true;
      else if (from == kFinite) from = origin[deps[j]];
    }
    double value = evaluate(ins, r, in, prog.constants.data());
    if (ins.op == Op::LoadConst) {
      r[i] = value, origin[i] = std::isfinite(value) ? kFinite : kConstant;
      continue;
    }
    if (!std::isfinite(value) && from == kFinite) {
      from = i;
      problems[i] = undefined ? "undefined value (" + num(value) + ")" : describeProblem(m, ins, r[ins.a], r[ins.b], value);
    }
    if (ins.op == Op::Store) {
      if (!std::isfinite(value)) return problems[from] + placeOf(m, prog, from, i, id, where);
      continue;
    }
    r[i] = value;
    origin[i] = std::isfinite(value) ? kFinite : from;
  }
  return "";
}

}  // namespace qdot::llvmbackend
