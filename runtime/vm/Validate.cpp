// bc::validate: everything the interpreter trusts without checking at run time — opcodes in
// range, operands inside the register file, constant registers never written, load indices
// inside their inputs, each function loading only what its ABI entry point passes, stores inside
// the outputs, one `ret` at the end, sizes and the CSC pattern consistent.
#include "qdot/bytecode.h"

namespace qdot::bc {
namespace {

struct Sizes {
  uint32_t variables, parameters, outputs, invariants, nonzeros;
};

uint32_t expectedOutputs(FunctionId id, const Sizes& s) {
  switch (id) {
    case FunctionId::Parameters: return s.parameters;
    case FunctionId::InitialValues: return 3 * s.variables;
    case FunctionId::Residual: return s.variables;
    case FunctionId::Jacobian: return s.nonzeros;
    case FunctionId::Outputs: return s.outputs;
    case FunctionId::Invariants: return s.invariants;
  }
  return 0;
}

// Which inputs each entry point passes.
bool loadAllowed(FunctionId id, Opcode op) {
  switch (op) {
    case Opcode::LoadConst: return true;
    case Opcode::LoadGiven:
    case Opcode::LoadOverridden: return id == FunctionId::Parameters;
    case Opcode::LoadTime:
    case Opcode::LoadP: return id != FunctionId::Parameters;
    case Opcode::LoadY:
    case Opcode::LoadYp: return id != FunctionId::Parameters && id != FunctionId::InitialValues;
    case Opcode::LoadCj: return id == FunctionId::Jacobian;
    default: return true;
  }
}

class FunctionChecker {
 public:
  FunctionChecker(const Module& m, FunctionId id, const Sizes& s) : m_(m), f_(m.function(id)), id_(id), s_(s) {}

  std::string check() {
    if (f_.outputCount != expectedOutputs(id_, s_)) return "wrong output count";
    if (f_.constants.size() > f_.registerCount) return "more constants than registers";
    size_t pc = 0;
    uint32_t instructions = 0;
    bool ended = false;
    while (pc < f_.code.size()) {
      if (ended) return "code after ret";
      if (f_.code[pc] >= kOpcodeCount) return "bad opcode " + std::to_string(f_.code[pc]) + at(pc);
      auto op = static_cast<Opcode>(f_.code[pc]);
      uint32_t n = operandCount(info(op).format);
      if (pc + n >= f_.code.size()) return "truncated instruction" + at(pc);
      std::string e = operands(op, &f_.code[pc + 1]);
      if (!e.empty()) return e + at(pc);
      ended = op == Opcode::Ret;
      pc += 1 + n, ++instructions;
    }
    if (!ended) return "does not end with ret";
    if (f_.sources.size() != instructions) return "source table size differs from the instruction count";
    for (uint32_t s : f_.sources)
      if (s != kNoSource && s >= m_.locations.size()) return "source index out of range";
    return "";
  }

 private:
  std::string at(size_t pc) const { return " at word " + std::to_string(pc); }
  bool dst(uint32_t r) const { return r >= f_.constants.size() && r < f_.registerCount; }
  bool src(uint32_t r) const { return r < f_.registerCount; }

  bool indexOk(Opcode op, uint32_t i) const {
    switch (op) {
      case Opcode::LoadY:
      case Opcode::LoadYp: return i < s_.variables;
      case Opcode::LoadP:
      case Opcode::LoadGiven:
      case Opcode::LoadOverridden: return i < s_.parameters;
      case Opcode::LoadConst: return i < f_.constants.size();
      default: return false;
    }
  }

  std::string operands(Opcode op, const uint32_t* o) const {
    if (!loadAllowed(id_, op)) return std::string(info(op).mnemonic) + " is not available in this function";
    bool ok = true;
    switch (info(op).format) {
      case Format::End: break;
      case Format::None: ok = dst(o[0]); break;
      case Format::Index: ok = dst(o[0]) && indexOk(op, o[1]); break;
      case Format::Unary:
      case Format::UnaryIndex: ok = dst(o[0]) && src(o[1]); break;
      case Format::Binary: ok = dst(o[0]) && src(o[1]) && src(o[2]); break;
      case Format::Ternary: ok = dst(o[0]) && src(o[1]) && src(o[2]) && src(o[3]); break;
      case Format::Store: ok = o[0] < f_.outputCount && src(o[1]); break;
    }
    return ok ? "" : std::string("operand out of range in ") + info(op).mnemonic;
  }

  const Module& m_;
  const Function& f_;
  FunctionId id_;
  Sizes s_;
};

std::string checkPattern(const Module& m) {
  size_t n = m.variableNames.size();
  const auto& starts = m.jacobianColumnStarts;
  const auto& rows = m.jacobianRowIndices;
  if (starts.size() != n + 1 || starts[0] != 0 || static_cast<size_t>(starts[n]) != rows.size())
    return "Jacobian column starts are inconsistent";
  for (size_t j = 0; j < n; ++j) {
    if (starts[j] > starts[j + 1]) return "Jacobian column starts decrease";
    for (int32_t k = starts[j]; k < starts[j + 1]; ++k)
      if (rows[k] < 0 || static_cast<size_t>(rows[k]) >= n || (k > starts[j] && rows[k] <= rows[k - 1]))
        return "Jacobian row indices out of range or not ascending in column " + std::to_string(j);
  }
  return "";
}

std::string checkModule(const Module& m) {
  size_t n = m.variableNames.size();
  if (m.isDifferential.size() != n || m.fixed.size() != n) return "per-variable tables have the wrong size";
  if (m.parameterDescriptions.size() != m.parameterNames.size()) return "parameter descriptions have the wrong size";
  if (std::string e = checkPattern(m); !e.empty()) return e;
  Sizes s{static_cast<uint32_t>(n), static_cast<uint32_t>(m.parameterNames.size()),
          static_cast<uint32_t>(m.outputNames.size()), static_cast<uint32_t>(m.invariantNames.size()),
          static_cast<uint32_t>(m.jacobianRowIndices.size())};
  for (uint32_t f = 0; f < kFunctionCount; ++f) {
    std::string e = FunctionChecker(m, static_cast<FunctionId>(f), s).check();
    if (!e.empty()) return std::string("function ") + kFunctionNames[f] + ": " + e;
  }
  return "";
}

}  // namespace

bool validate(const Module& m, std::string& error) {
  error = checkModule(m);
  return error.empty();
}

}  // namespace qdot::bc
