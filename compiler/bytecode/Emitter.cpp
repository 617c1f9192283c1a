// emitFunction: linear-scan register assignment over the kernel's SSA program. Operands dying at
// an instruction are released before its result is assigned, so the result may reuse an operand's
// register (VM handlers read operands first). `ldk` emits nothing: constants live in registers
// [0, pool size), preloaded once by the VM. A loop body runs again after its last instruction, so
// a value from before the loop that the body reads lives until the `endloop`; the body's own values
// are read only inside it, and their registers are reused as in straight-line code.
#include "bytecode/Emitter.h"

#include <unordered_map>

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
    uint32_t body = kUnused;  // first instruction of the open loop body
    std::vector<uint32_t> outer;  // values from before the open loop that its body reads
    for (uint32_t i = 0; i < p.code.size(); ++i) {
      uint32_t ops[3];
      for (uint32_t k = 0, n = operandsOf(p.code[i], ops); k < n; ++k) {
        lastUse_[ops[k]] = i;
        if (body != kUnused && ops[k] < body) outer.push_back(ops[k]);
      }
      if (p.code[i].op == kernel::Op::LoadConst) physical_[i] = p.code[i].imm;
      if (p.code[i].op == kernel::Op::LoopBegin) body = i + 1;
      if (p.code[i].op == kernel::Op::LoopEnd) {
        for (uint32_t v : outer)
          if (lastUse_[v] != i) lastUse_[v] = i, diesAtLoopEnd_[i].push_back(v);
        outer.clear(), body = kUnused;
      }
    }
  }

  bc::Function run() {
    bc::Function f;
    f.constants = p_.constants;
    f.outputCount = p_.outputCount;
    f.loops = p_.loops;
    f.indexTable = p_.indexTable;
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
    if (bc::isLoopControl(fmt)) return encodeLoopControl(i, f);
    if (bc::isStore(fmt)) {
      f.code.push_back(ins.imm), f.code.push_back(phys[0]);
      return;
    }
    physical_[i] = allocate();
    f.code.push_back(physical_[i]);
    for (uint32_t k = 0; k < n; ++k) f.code.push_back(phys[k]);
    if (fmt == bc::Format::Index || fmt == bc::Format::UnaryIndex) f.code.push_back(ins.imm);
    if (lastUse_[i] == kUnused) release(i);  // a value nobody reads
  }

  // `loop l, exit` (exit: words from its opcode to after the endloop, patched there), `endloop l`.
  void encodeLoopControl(uint32_t i, bc::Function& f) {
    f.code.push_back(p_.code[i].imm);
    if (p_.code[i].op == kernel::Op::LoopBegin) {
      loopWord_ = f.code.size() - 2;
      f.code.push_back(0);
      return;
    }
    f.code[loopWord_ + 2] = static_cast<uint32_t>(f.code.size() - loopWord_);
    if (auto it = diesAtLoopEnd_.find(i); it != diesAtLoopEnd_.end())
      for (uint32_t v : it->second)
        if (lastUse_[v] == i) release(v);
  }

  const kernel::Program& p_;
  std::vector<uint32_t> physical_;  // value -> register
  std::vector<uint32_t> lastUse_;   // value -> last instruction reading it
  std::vector<uint32_t> free_;
  uint32_t next_ = 0;
  std::unordered_map<uint32_t, std::vector<uint32_t>> diesAtLoopEnd_;  // endloop -> outer values it frees
  size_t loopWord_ = 0;  // word of the open loop's opcode

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
