// execute (the fast loop of DispatchLoop.h) and diagnose: the slow re-run that follows every
// non-finite value back to the instruction that produced it from finite operands. Only the
// operands an instruction depends on count (for a select: the condition and the branch taken),
// so a NaN in an untaken branch is never blamed.
#include <charconv>
#include <unordered_map>

#include "vm/DispatchLoop.h"

namespace qdot::vm {
namespace {

constexpr uint32_t kFinite = UINT32_MAX;        // origin of a finite value
constexpr uint32_t kConstant = UINT32_MAX - 1;  // a non-finite constant of the pool

// Executes the single instruction at ip (same handlers as the fast loops).
void step(const uint32_t* ip, double* r, const Inputs& in, const double* k, double* out) {
  QDOT_VM_INPUTS
  switch (static_cast<bc::Opcode>(*ip)) {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) \
  case bc::Opcode::Name:                           \
    QDOT_VM_##Format(Value) break;
#include "qdot/opcodes.def"
  }
}

std::string num(double v) {
  char buf[32];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

std::string nameAt(const std::vector<std::string>& names, uint32_t i) { return i < names.size() ? names[i] : "?"; }

// Why instruction `ip` produced a non-finite value from finite operands A, B (or from nothing, for loads).
std::string describeProblem(const bc::Module& m, const uint32_t* ip, double A, double B, double value) {
  auto op = static_cast<bc::Opcode>(*ip);
  switch (op) {
    case bc::Opcode::Sqrt: return "sqrt of a negative number (" + num(A) + ")";
    case bc::Opcode::Log: return A == 0.0 ? "log of zero" : "log of a negative number (" + num(A) + ")";
    case bc::Opcode::Asin:
    case bc::Opcode::Acos: return std::string(bc::info(op).mnemonic) + " of a number outside [-1, 1] (" + num(A) + ")";
    case bc::Opcode::Div: return B == 0.0 ? "division by zero (" + num(A) + "/0)" : "overflow in " + num(A) + "/" + num(B);
    case bc::Opcode::Pow:
      if (A < 0.0 && B != std::trunc(B)) return "power of a negative number (" + num(A) + "^" + num(B) + ")";
      return A == 0.0 ? "zero to a negative power (0^" + num(B) + ")" : "overflow in " + num(A) + "^" + num(B);
    case bc::Opcode::Powi: {
      std::string e = std::to_string(static_cast<int32_t>(ip[3]));
      return A == 0.0 ? "zero to a negative power (0^" + e + ")" : "overflow in " + num(A) + "^" + e;
    }
    case bc::Opcode::LoadY: return "the value of " + nameAt(m.variableNames, ip[2]) + " is " + num(value);
    case bc::Opcode::LoadYp: return "the value of der(" + nameAt(m.variableNames, ip[2]) + ") is " + num(value);
    case bc::Opcode::LoadP: return "parameter " + nameAt(m.parameterNames, ip[2]) + " is " + num(value);
    case bc::Opcode::LoadGiven:
      return "the value given for parameter " + nameAt(m.parameterNames, ip[2]) + " is " + num(value);
    case bc::Opcode::LoadTime: return "time is " + num(value);
    case bc::Opcode::LoadCj: return "cj is " + num(value);
    default: break;
  }
  return "overflow in " + std::string(bc::info(op).mnemonic) + " (" + num(value) + ")";
}

// " in <label> at <where>" of the culprit; when the value it spoiled belongs to another source (a
// shared subexpression), that one is named too.
std::string placeOf(const bc::Module& m, const bc::Function& f, uint32_t culprit, uint32_t store, bc::FunctionId id) {
  auto label = [&](uint32_t ordinal) {
    uint32_t loc = ordinal < f.sources.size() ? f.sources[ordinal] : bc::kNoSource;
    if (loc >= m.locations.size()) return std::string();
    const bc::Location& l = m.locations[loc];
    return l.label + (l.where.empty() ? "" : " at " + l.where);
  };
  std::string where = label(culprit), spoiled = label(store), s;
  if (!where.empty()) s = " in " + where;
  if (!spoiled.empty() && spoiled != where) s += ", which makes " + spoiled + " non-finite";
  if (id != bc::FunctionId::Residual) s += std::string(" (computing ") + bc::kFunctionNames[static_cast<int>(id)] + ")";
  return s;
}

// The registers whose values the result of instruction `ip` depends on.
uint32_t dependencies(const uint32_t* ip, const double* r, uint32_t deps[3]) {
  auto op = static_cast<bc::Opcode>(*ip);
  bc::Format fmt = bc::info(op).format;
  if (op == bc::Opcode::Select) {
    deps[0] = ip[2], deps[1] = r[ip[2]] != 0.0 ? ip[3] : ip[4];
    return 2;
  }
  if (fmt == bc::Format::Store) return deps[0] = ip[2], 1;
  uint32_t n = fmt == bc::Format::Unary || fmt == bc::Format::UnaryIndex ? 1 : fmt == bc::Format::Binary ? 2 : 0;
  for (uint32_t i = 0; i < n; ++i) deps[i] = ip[2 + i];
  return n;
}

}  // namespace

void execute(const bc::Function& f, double* registers, const Inputs& in, double* out) {
#if (defined(__GNUC__) || defined(__clang__)) && !defined(QDOT_VM_NO_COMPUTED_GOTO)
  detail::loopComputedGoto(f.code.data(), registers, in, f.constants.data(), out);
#else
  detail::loopSwitch(f.code.data(), registers, in, f.constants.data(), out);
#endif
}

void executeWithSwitch(const bc::Function& f, double* registers, const Inputs& in, double* out) {
  detail::loopSwitch(f.code.data(), registers, in, f.constants.data(), out);
}

std::vector<double> makeRegisters(const bc::Function& f) {
  std::vector<double> r(f.registerCount, 0.0);
  std::copy(f.constants.begin(), f.constants.end(), r.begin());
  return r;
}

namespace {

// The operand values an instruction reads (A, B), taken before it runs (its result may reuse a register).
std::pair<double, double> operandValues(const uint32_t* ip, const double* r) {
  switch (bc::info(static_cast<bc::Opcode>(*ip)).format) {
    case bc::Format::Unary:
    case bc::Format::UnaryIndex:
    case bc::Format::Store: return {r[ip[2]], 0.0};
    case bc::Format::Binary:
    case bc::Format::Ternary: return {r[ip[2]], r[ip[3]]};
    default: return {0.0, 0.0};
  }
}

}  // namespace

std::string diagnose(const bc::Module& m, bc::FunctionId id, double* r, const Inputs& in, double* out) {
  const bc::Function& f = m.function(id);
  std::vector<uint32_t> origin(f.registerCount, kFinite);
  for (uint32_t i = 0; i < f.constants.size(); ++i)
    if (!std::isfinite(r[i])) origin[i] = kConstant;
  std::unordered_map<uint32_t, std::string> problems;  // culprit ordinal -> what went wrong
  uint32_t ordinal = 0;
  for (const uint32_t* ip = f.code.data(); *ip != static_cast<uint32_t>(bc::Opcode::Ret); ++ordinal) {
    auto op = static_cast<bc::Opcode>(*ip);
    uint32_t deps[3], from = kFinite;
    bool undefined = false;  // depends on a NaN/inf constant (e.g. a parameter without a value)
    for (uint32_t i = 0, n = dependencies(ip, r, deps); i < n; ++i) {
      if (std::isfinite(r[deps[i]])) continue;
      if (origin[deps[i]] == kConstant) undefined = true;
      else if (from == kFinite) from = origin[deps[i]];
    }
    auto [A, B] = operandValues(ip, r);
    step(ip, r, in, f.constants.data(), out);
    double value = op == bc::Opcode::Store ? out[ip[1]] : r[ip[1]];
    if (!std::isfinite(value) && from == kFinite) {
      from = ordinal;
      problems[ordinal] = undefined ? "undefined value (" + num(value) + ")" : describeProblem(m, ip, A, B, value);
    }
    if (op == bc::Opcode::Store && !std::isfinite(value)) return problems[from] + placeOf(m, f, from, ordinal, id);
    if (op != bc::Opcode::Store) origin[ip[1]] = std::isfinite(value) ? kFinite : from;
    ip += 1 + bc::operandCount(bc::info(op).format);
  }
  return "";
}

}  // namespace qdot::vm
