// emitFunction: linear-scan register assignment over the kernel's straight-line SSA program.
// Operands dying at an instruction are released before its result is assigned, so the result may
// reuse an operand's register (VM handlers read operands first). `ldk` emits nothing: constants
// live in registers [0, pool size), preloaded once by the VM.
#include "bytecode/Emitter.h"

#include "vm/Vm.h"

namespace qdot::bytecode {
namespace {

constexpr uint32_t kUnused = UINT32_MAX;

// Kernel and bytecode number opcodes the same way (both come from qdot/opcodes.def).
static_assert(static_cast<int>(kernel::Op::Store) == static_cast<int>(bc::Opcode::Store));

// The registers an instruction reads (a, b, c: as many as its format reads).
uint32_t operandsOf(const kernel::Instr& ins, uint32_t out[3]) {
  out[0] = ins.a, out[1] = ins.b, out[2] = ins.c;
  return bc::readCount(bc::info(static_cast<bc::Opcode>(ins.op)).format);
}

class Allocator {
 public:
  explicit Allocator(const kernel::Program& p) : p_(p), physical_(p.code.size(), kUnused), lastUse_(p.code.size(), kUnused) {
    next_ = static_cast<uint32_t>(p.constants.size());
    for (uint32_t i = 0; i < p.code.size(); ++i) {
      uint32_t ops[3];
      for (uint32_t k = 0, n = operandsOf(p.code[i], ops); k < n; ++k) lastUse_[ops[k]] = i;
      if (p.code[i].op == kernel::Op::LoadConst) physical_[i] = p.code[i].imm;
    }
  }

  bc::Function run() {
    bc::Function f;
    f.constants = p_.constants;
    f.outputCount = p_.outputCount;
    for (uint32_t i = 0; i < p_.code.size(); ++i)
      if (p_.code[i].op != kernel::Op::LoadConst) encode(i, f);
    f.code.push_back(static_cast<uint32_t>(bc::Opcode::Ret));
    f.sources.push_back(bc::kNoSource);
    f.registerCount = next_;
    return f;
  }

 private:
  void release(uint32_t value) {
    if (physical_[value] >= p_.constants.size()) free_.push_back(physical_[value]);
  }
  uint32_t allocate() {
    if (free_.empty()) return next_++;
    uint32_t r = free_.back();
    free_.pop_back();
    return r;
  }

  void encode(uint32_t i, bc::Function& f) {
    const kernel::Instr& ins = p_.code[i];
    bc::Format fmt = bc::info(static_cast<bc::Opcode>(ins.op)).format;
    uint32_t ops[3], n = operandsOf(ins, ops);
    uint32_t phys[3] = {0, 0, 0};
    for (uint32_t k = 0; k < n; ++k) phys[k] = physical_[ops[k]];
    for (uint32_t k = 0; k < n; ++k)  // each dying operand once
      if (lastUse_[ops[k]] == i && (k == 0 || ops[k] != ops[k - 1]) && (k < 2 || ops[k] != ops[0])) release(ops[k]);
    f.code.push_back(static_cast<uint32_t>(ins.op));
    f.sources.push_back(ins.source);
    if (fmt == bc::Format::Store) {
      f.code.push_back(ins.imm), f.code.push_back(phys[0]);
      return;
    }
    physical_[i] = allocate();
    f.code.push_back(physical_[i]);
    for (uint32_t k = 0; k < n; ++k) f.code.push_back(phys[k]);
    if (fmt == bc::Format::Index || fmt == bc::Format::UnaryIndex) f.code.push_back(ins.imm);
    if (lastUse_[i] == kUnused) release(i);  // a value nobody reads
  }

  const kernel::Program& p_;
  std::vector<uint32_t> physical_;  // value -> register
  std::vector<uint32_t> lastUse_;   // value -> last instruction reading it
  std::vector<uint32_t> free_;
  uint32_t next_ = 0;
};

}  // namespace

bc::Function emitFunction(const kernel::Program& p) { return Allocator(p).run(); }

bc::Module emitBytecode(const kernel::KernelModule& k, const SourceManager& sm) {
  bc::Module m;
  m.description = k.description;
  for (size_t f = 0; f < kModelProgramCount; ++f) m.functions[f] = emitFunction(k.programs[f]);
  for (const kernel::Source& s : k.sources)
    m.locations.push_back({s.label, kernel::describeLocation(sm, s.range), s.text});
  return m;
}

void printBytecode(std::ostream& os, const bc::Module& m) { vm::disassemble(os, m); }

}  // namespace qdot::bytecode
