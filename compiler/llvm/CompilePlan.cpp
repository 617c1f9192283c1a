// splitProgram and planCompile: see CompilePlan.h.
#include "llvm/CompilePlan.h"

#include <algorithm>
#include <map>

namespace qdot::llvmbackend {

bool rematerialisable(kernel::Op op) {
  using kernel::Op;
  switch (op) {
    case Op::LoadTime: case Op::LoadCj: case Op::LoadY: case Op::LoadYp: case Op::LoadP:
    case Op::LoadGiven: case Op::LoadOverridden: case Op::LoadConst: return true;
    default: return false;
  }
}

namespace {

// The first instruction of each part: every `chunk` instructions, except that a cut inside a loop
// moves to the loop's `loop` (or past its `endloop` if that would leave the part empty).
std::vector<uint32_t> partStarts(const kernel::Program& p, uint32_t chunk) {
  const size_t n = p.code.size();
  std::vector<uint32_t> loopBegin(n, UINT32_MAX), loopEnd(n, 0);  // per instruction of a loop
  for (size_t i = 0, b = UINT32_MAX; i < n; ++i) {
    if (p.code[i].op == kernel::Op::LoopBegin) b = i;
    if (b != UINT32_MAX) loopBegin[i] = static_cast<uint32_t>(b);
    if (p.code[i].op == kernel::Op::LoopEnd) {
      for (size_t j = b; j <= i; ++j) loopEnd[j] = static_cast<uint32_t>(i);
      b = UINT32_MAX;
    }
  }
  std::vector<uint32_t> starts{0};
  for (size_t start = 0, cut; (cut = start + chunk) < n; start = cut) {
    if (loopBegin[cut] != UINT32_MAX && loopBegin[cut] < cut)  // instructions cut-1 and cut share a loop
      cut = loopBegin[cut] > start ? loopBegin[cut] : loopEnd[cut] + 1;
    if (cut >= n) break;
    starts.push_back(static_cast<uint32_t>(cut));
  }
  return starts;
}

}  // namespace

ProgramSplit splitProgram(const kernel::Program& p, uint32_t maxInstructions) {
  ProgramSplit s;
  size_t n = p.code.size();
  s.starts = partStarts(p, std::max<uint32_t>(1, maxInstructions));
  s.parts = static_cast<uint32_t>(s.starts.size());
  s.spillSlot.assign(n, ProgramSplit::kNoSlot);
  std::vector<uint32_t> part(n, 0);
  for (uint32_t k = 0; k < s.parts; ++k)
    std::fill(part.begin() + s.begin(k), part.begin() + s.end(k, n), k);
  auto partOf = [&](size_t i) { return part[i]; };
  for (size_t i = 0; i < n; ++i) {
    const kernel::Instr& ins = p.code[i];
    const uint32_t operands[3] = {ins.a, ins.b, ins.c};
    for (uint32_t j = 0, e = kernel::readCount(ins.op); j < e; ++j) {
      uint32_t v = operands[j];
      if (partOf(v) != partOf(i) && !rematerialisable(p.code[v].op) && s.spillSlot[v] == ProgramSplit::kNoSlot)
        s.spillSlot[v] = s.spillSlots++;
    }
  }
  return s;
}

std::string entryName(const kernel::Program& p, ModelProgram program) {
  return "qdot_" + (p.name.empty() ? std::to_string(programIndex(program)) : p.name);
}

std::string partName(const std::string& name, uint32_t k) { return name + "." + std::to_string(k); }

int levelOf(ModelProgram program, const JitOptions& o) {
  if (program == ModelProgram::Residual) return o.optLevel;
  if (program == ModelProgram::Jacobian) return o.jacobianOptLevel >= 0 ? o.jacobianOptLevel : o.optLevel;
  return o.coldOptLevel;
}

CompilePlan planCompile(const kernel::KernelModule& k, const JitOptions& o, unsigned threads) {
  size_t total = 0;
  for (size_t i = 0; i < kModelProgramCount; ++i)
    if (o.compiledPrograms & programBit(programAt(i))) total += k.programs[i].code.size();
  bool large = total > o.largeModelInstructions;
  // At most 100 000 instructions (~0.1 s at level 0): a cancelled compile stops within a unit.
  size_t budget = std::min<size_t>(std::max<size_t>(size_t{4} * o.maxInstructionsPerFunction, total / (2 * threads)),
                                   std::max<size_t>(100000, o.maxInstructionsPerFunction));
  CompilePlan plan;
  std::map<int, size_t> filling;  // level -> index of the unit being filled at that level
  for (size_t i = 0; i < kModelProgramCount; ++i) {
    ModelProgram id = programAt(i);
    if (!(o.compiledPrograms & programBit(id))) continue;
    const kernel::Program& prog = k.programs[i];
    ProgramPlan& p = plan.programs[i];
    p.compiled = true;
    p.name = entryName(prog, id);
    p.split = splitProgram(prog, o.maxInstructionsPerFunction);
    p.level = large ? 0 : levelOf(id, o);
    for (uint32_t part = 0; part < p.split.parts; ++part) {
      auto it = filling.find(p.level);
      if (it == filling.end() || plan.units[it->second].instructions >= budget) {
        plan.units.push_back(PlannedUnit{p.level, {}, 0});
        it = filling.insert_or_assign(p.level, plan.units.size() - 1).first;
      }
      PlannedUnit& u = plan.units[it->second];
      if (u.segments.empty() || u.segments.back().program != id) u.segments.push_back({id, part, part});
      u.segments.back().last = part + 1;
      u.instructions += p.split.end(part, prog.code.size()) - p.split.begin(part);
    }
  }
  return plan;
}

}  // namespace qdot::llvmbackend
