// bc::validate: everything the interpreter trusts without checking at run time — opcodes in
// range, operands inside the register file, constant registers never written, load indices
// inside their inputs, each function loading only what its ABI entry point passes (qdot/programs.def),
// stores inside the outputs, one `ret` at the end, the description (sizes, CSC pattern) consistent.
#include "qdot/bytecode.h"

namespace qdot::bc {
namespace {

// Which inputs each entry point passes (qdot/programs.def).
bool loadAllowed(ModelProgram program, Opcode op) {
  uint32_t inputs = programInputs(program);
  switch (op) {
    case Opcode::LoadTime: return inputs & InputTime;
    case Opcode::LoadCj: return inputs & InputCj;
    case Opcode::LoadY: return inputs & InputY;
    case Opcode::LoadYp: return inputs & InputYp;
    case Opcode::LoadP: return inputs & InputP;
    case Opcode::LoadGiven: return inputs & InputGiven;
    case Opcode::LoadOverridden: return inputs & InputOverridden;
    default: return true;
  }
}

class FunctionChecker {
 public:
  FunctionChecker(const Module& m, ModelProgram program) : m_(m), d_(m.description), f_(m.function(program)), program_(program) {}

  std::string check() {
    if (f_.outputCount != d_.outputCount(program_)) return "wrong output count";
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
      std::string e = operands(&f_.code[pc]);
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
      case Opcode::LoadYp: return i < d_.variableCount();
      case Opcode::LoadP:
      case Opcode::LoadGiven:
      case Opcode::LoadOverridden: return i < d_.parameterCount();
      case Opcode::LoadConst: return i < f_.constants.size();
      default: return false;
    }
  }

  // The operands of the instruction at ip, by its format (the arity table of qdot/bytecode.h).
  std::string operands(const uint32_t* ip) const {
    Instruction ins = decode(ip);
    Format f = info(ins.op).format;
    if (!loadAllowed(program_, ins.op)) return std::string(info(ins.op).mnemonic) + " is not available in this function";
    const uint32_t reads[3] = {ins.a, ins.b, ins.c};
    bool ok = !definesRegister(f) || dst(ins.dest);
    for (uint32_t i = 0; i < readCount(f); ++i) ok = ok && src(reads[i]);
    if (f == Format::Index) ok = ok && indexOk(ins.op, ins.imm);
    if (f == Format::Store) ok = ok && ins.imm < f_.outputCount;
    return ok ? "" : std::string("operand out of range in ") + info(ins.op).mnemonic;
  }

  const Module& m_;
  const ModelDescription& d_;
  const Function& f_;
  ModelProgram program_;
};

std::string checkModule(const Module& m) {
  if (std::string e = m.description.inconsistency(); !e.empty()) return e;
  for (size_t f = 0; f < kModelProgramCount; ++f) {
    std::string e = FunctionChecker(m, programAt(f)).check();
    if (!e.empty()) return std::string("function ") + kModelProgramNames[f] + ": " + e;
  }
  return "";
}

}  // namespace

Status validate(const Module& m) {
  if (std::string e = checkModule(m); !e.empty()) return Error{std::move(e)};
  return {};
}

}  // namespace qdot::bc
