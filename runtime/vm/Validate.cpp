// bc::validate: everything the interpreter trusts without checking at run time — opcodes in
// range, operands inside the register file, constant registers never written, load indices
// inside their inputs, each function loading only what its ABI entry point passes (qdot/programs.def),
// stores inside the outputs, one `ret` at the end, the description (sizes, CSC pattern) consistent.
// Loops (qdot/loop.hpp): not nested, each used once, looped opcodes only in a body, every index a
// looped instruction reaches inside its input, outputs or table (checked at the loop's smallest
// and largest offset), and a register written in a body read only in that body after the write.
#include "qdot/bytecode.h"

namespace qdot::bc {
namespace {

// The opcodes that use the loop state (c, L), allowed only inside a loop body.
bool isLooped(Opcode op) {
  return op == Opcode::LoadYLooped || op == Opcode::LoadYpLooped || op == Opcode::LoadPLooped ||
         op == Opcode::LoadLoopOffset || op == Opcode::StoreLooped || op == Opcode::StoreIndexed ||
         op == Opcode::LoadTable;
}

// Which inputs each entry point passes (qdot/programs.def).
bool loadAllowed(ModelProgram program, Opcode op) {
  uint32_t inputs = programInputs(program);
  switch (op) {
    case Opcode::LoadTime: return inputs & InputTime;
    case Opcode::LoadCj: return inputs & InputCj;
    case Opcode::LoadY:
    case Opcode::LoadYLooped: return inputs & InputY;
    case Opcode::LoadYp:
    case Opcode::LoadYpLooped: return inputs & InputYp;
    case Opcode::LoadP:
    case Opcode::LoadPLooped: return inputs & InputP;
    case Opcode::LoadGiven: return inputs & InputGiven;
    case Opcode::LoadOverridden: return inputs & InputOverridden;
    default: return true;
  }
}

class FunctionChecker {
 public:
  FunctionChecker(const Module& m, ModelProgram program)
      : m_(m), d_(m.description), f_(m.function(program)), program_(program), used_(f_.loops.size(), 0) {}

  std::string check() {
    if (f_.outputCount != d_.outputCount(program_)) return "wrong output count";
    if (f_.constants.size() > f_.registerCount) return "more constants than registers";
    written_.assign(f_.registerCount, kOutside);
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
      if (e.empty()) e = loopRules(&f_.code[pc], pc);
      if (e.empty()) e = registerRules(decode(&f_.code[pc]));
      if (!e.empty()) return e + at(pc);
      ended = op == Opcode::Ret;
      pc += 1 + n, ++instructions;
    }
    if (!ended) return "does not end with ret";
    if (open_ != kNone) return std::string("loop ").append(std::to_string(open_)) + " has no endloop";
    if (f_.sources.size() != instructions) return "source table size differs from the instruction count";
    for (uint32_t s : f_.sources)
      if (s != kNoSource && s >= m_.locations.size()) return "source index out of range";
    return "";
  }

 private:
  static constexpr uint32_t kNone = UINT32_MAX;
  // Where the value in a register was written: outside loops, in the open body, in a closed body
  // (unreadable until written again); or read in the open body before the body writes it.
  enum Written : uint8_t { kOutside, kOpenBody, kClosedBody, kReadFromOutside };

  std::string at(size_t pc) const { return " at word " + std::to_string(pc); }
  static std::string reg(uint32_t r) { return std::string("r").append(std::to_string(r)); }
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
      case Opcode::LoadYLooped:
      case Opcode::LoadYpLooped:
      case Opcode::LoadPLooped:
      case Opcode::LoadTable: return true;  // with the loop's offsets or its count: loopRules
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
    if (f == Format::Store || f == Format::StoreAdd) ok = ok && ins.imm < f_.outputCount;
    return ok ? "" : std::string("operand out of range in ") + info(ins.op).mnemonic;
  }

  // Loop structure and the indices looped instructions reach.
  std::string loopRules(const uint32_t* ip, size_t pc) {
    Instruction ins = decode(ip);
    const char* name = info(ins.op).mnemonic;
    if (ins.op == Opcode::LoopBegin) return beginLoop(ins.imm, pc);
    if (ins.op == Opcode::LoopEnd) return endLoop(ins.imm, pc);
    if (!isLooped(ins.op)) return "";
    if (open_ == kNone) return std::string(name) + " outside a loop";
    if (!iterates_) return "";
    int64_t lo = int64_t{ins.imm} + range_.min, hi = int64_t{ins.imm} + range_.max;
    switch (ins.op) {
      case Opcode::LoadYLooped:
      case Opcode::LoadYpLooped: return lo >= 0 && hi < int64_t(d_.variableCount()) ? "" : std::string(name) + " index out of range";
      case Opcode::LoadPLooped: return lo >= 0 && hi < int64_t(d_.parameterCount()) ? "" : "ldpl index out of range";
      case Opcode::StoreLooped: return lo >= 0 && hi < int64_t{f_.outputCount} ? "" : "stl slot out of range";
      case Opcode::StoreIndexed: return indexedSlotsOk(ins.imm) ? "" : "stx index table position or slot out of range";
      case Opcode::LoadTable: return tableReaches(ins.imm) ? "" : "ldx index table position out of range";
      default: return "";
    }
  }

  std::string beginLoop(uint32_t id, size_t pc) {
    if (open_ != kNone) return std::string("nested loop (loop ").append(std::to_string(open_)) + " is open)";
    if (id >= f_.loops.size()) return "loop id out of range";
    if (used_[id]++) return std::string("loop ").append(std::to_string(id)) + " used twice";
    const Loop& l = f_.loops[id];
    iterates_ = offsetRange(l, f_.indexTable, range_);
    if (l.count && !iterates_) return "loop offset table out of range";
    open_ = id, openPc_ = pc;
    return "";
  }

  std::string endLoop(uint32_t id, size_t pc) {
    if (open_ == kNone || id != open_) return std::string("endloop ").append(std::to_string(id)) + " does not close the open loop";
    if (f_.code[openPc_ + 2] != pc + 2 - openPc_) return "loop exit does not point after its endloop";
    for (uint32_t r : body_) written_[r] = written_[r] == kOpenBody ? kClosedBody : kOutside;
    body_.clear();
    open_ = kNone;
    return "";
  }

  bool tableReaches(uint32_t base) const {
    uint32_t count = f_.loops[open_].count;
    return base <= f_.indexTable.size() && f_.indexTable.size() - base >= count;
  }
  bool indexedSlotsOk(uint32_t base) const {
    uint32_t count = f_.loops[open_].count;
    if (base > f_.indexTable.size() || f_.indexTable.size() - base < count) return false;
    for (uint32_t c = 0; c < count; ++c)
      if (f_.indexTable[base + c] >= f_.outputCount) return false;
    return true;
  }

  // A register written in a loop body is read only in that body, after the write.
  std::string registerRules(const Instruction& ins) {
    Format f = info(ins.op).format;
    const uint32_t reads[3] = {ins.a, ins.b, ins.c};
    for (uint32_t i = 0; i < readCount(f); ++i) {
      Written& w = written_[reads[i]];
      if (w == kClosedBody) return reg(reads[i]) + ", written in a loop body, is read after its endloop";
      if (open_ != kNone && w == kOutside) w = kReadFromOutside, body_.push_back(reads[i]);
    }
    if (!definesRegister(f)) return "";
    Written& w = written_[ins.dest];
    if (open_ == kNone) {
      w = kOutside;
      return "";
    }
    if (w == kReadFromOutside) return reg(ins.dest) + " is read in a loop body before the body writes it";
    if (w != kOpenBody) body_.push_back(ins.dest);
    w = kOpenBody;
    return "";
  }

  const Module& m_;
  const ModelDescription& d_;
  const Function& f_;
  ModelProgram program_;
  std::vector<uint8_t> used_;      // per loop id: begun already
  std::vector<Written> written_;   // per register
  std::vector<uint32_t> body_;     // registers the open body wrote or read from outside
  uint32_t open_ = kNone;          // the open loop's id
  size_t openPc_ = 0;              // the word of its `loop`
  bool iterates_ = false;          // it has iterations; range_ holds its offsets
  OffsetRange range_;
};

std::string checkModule(const Module& m) {
  if (std::string e = m.description->inconsistency(); !e.empty()) return e;
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
