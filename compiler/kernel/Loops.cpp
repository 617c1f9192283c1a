// Loops of the kernel IR (Kernel.h): checkLoops, the loop rules checked on the kernel program itself
// for the backends that do not go through the bytecode validator (the JIT and object files compile
// the kernel directly, and a looped store outside its outputs would write out of bounds), and
// executedInstructions, the work of one call.
#include <algorithm>
#include <unordered_map>

#include "kernel/Kernel.h"

namespace qdot::kernel {
namespace {

constexpr uint32_t kNone = UINT32_MAX;

bool isLooped(Op op) {
  return op == Op::LoadYLooped || op == Op::LoadYpLooped || op == Op::LoadPLooped || op == Op::LoadLoopOffset ||
         op == Op::StoreLooped || op == Op::StoreIndexed || op == Op::LoadTable;
}

std::string at(size_t i) { return std::string(" at instruction ").append(std::to_string(i)); }

class LoopChecker {
 public:
  LoopChecker(const Program& p, size_t variables, size_t parameters)
      : p_(p), variables_(variables), parameters_(parameters), bodyOf_(p.code.size(), kNone) {}

  std::string check() {
    std::vector<uint8_t> used(p_.loops.size(), 0);
    for (size_t i = 0; i < p_.code.size(); ++i) {
      const Instr& ins = p_.code[i];
      std::string e = ins.op == Op::LoopBegin ? begin(ins.imm, used) : ins.op == Op::LoopEnd ? end(ins.imm) : "";
      if (e.empty() && isLooped(ins.op)) e = open_ == kNone ? std::string(mnemonic(ins.op)) + " outside a loop" : reach(ins);
      if (e.empty()) e = operands(ins, i);
      if (!e.empty()) return e + at(i);
      bodyOf_[i] = ins.op == Op::LoopEnd ? kNone : open_;
    }
    return open_ == kNone ? "" : "a loop has no endloop";
  }

 private:
  std::string begin(uint32_t id, std::vector<uint8_t>& used) {
    if (open_ != kNone) return "nested loop";
    if (id >= p_.loops.size() || used[id]++) return "loop id out of range or used twice";
    iterates_ = offsetRange(p_.loops[id], p_.indexTable, range_);
    if (p_.loops[id].count && !iterates_) return "loop offset table out of range";
    open_ = id;
    return "";
  }
  std::string end(uint32_t id) {
    if (id != open_) return "endloop does not close the open loop";
    open_ = kNone;
    return "";
  }
  // The indices a looped instruction reaches at the loop's smallest and largest offsets.
  std::string reach(const Instr& ins) const {
    if (!iterates_) return "";
    int64_t lo = int64_t{ins.imm} + range_.min, hi = int64_t{ins.imm} + range_.max;
    bool ok = true;
    if (ins.op == Op::LoadYLooped || ins.op == Op::LoadYpLooped) ok = lo >= 0 && hi < int64_t(variables_);
    if (ins.op == Op::LoadPLooped) ok = lo >= 0 && hi < int64_t(parameters_);
    if (ins.op == Op::StoreLooped) ok = lo >= 0 && hi < int64_t{p_.outputCount};
    if (ins.op == Op::LoadTable) {
      uint32_t count = p_.loops[open_].count;
      ok = ins.imm <= p_.indexTable.size() && p_.indexTable.size() - ins.imm >= count;
    }
    if (ins.op == Op::StoreIndexed) {
      uint32_t count = p_.loops[open_].count;
      ok = ins.imm <= p_.indexTable.size() && p_.indexTable.size() - ins.imm >= count;
      uint32_t largest = 0;  // without a branch per entry: the Jacobian's table has one per nonzero
      if (ok)
        for (uint32_t c = 0; c < count; ++c) largest = std::max(largest, p_.indexTable[ins.imm + c]);
      ok = ok && (count == 0 || largest < p_.outputCount);
    }
    return ok ? "" : std::string(mnemonic(ins.op)) + " index out of range";
  }
  // Operands are earlier registers; one defined in a loop body is read only in that body.
  std::string operands(const Instr& ins, size_t i) const {
    const uint32_t reads[3] = {ins.a, ins.b, ins.c};
    for (uint32_t k = 0; k < readCount(ins.op); ++k) {
      std::string reg = std::string("%").append(std::to_string(reads[k]));
      if (reads[k] >= i) return "operand " + reg + " is not an earlier register";
      uint32_t body = bodyOf_[reads[k]];
      if (body != kNone && body != open_) return reg + ", defined in loop " + std::to_string(body) + ", is read outside it";
    }
    return "";
  }

  const Program& p_;
  size_t variables_, parameters_;
  std::vector<uint32_t> bodyOf_;  // per instruction: the loop whose body holds it, or kNone
  uint32_t open_ = kNone;
  bool iterates_ = false;
  OffsetRange range_;
};

}  // namespace

std::string checkLoops(const Program& p, size_t variableCount, size_t parameterCount) {
  return LoopChecker(p, variableCount, parameterCount).check();
}

void hoistLoopConstants(Program& p) {
  if (p.loops.empty()) return;
  std::vector<Instr> code;
  code.reserve(p.code.size());
  std::vector<uint32_t> renamed(p.code.size(), kNone);  // old register -> new
  auto rename = [&](Instr ins) {
    for (uint32_t k = 0; k < readCount(ins.op); ++k) {
      uint32_t& r = k == 0 ? ins.a : k == 1 ? ins.b : ins.c;
      r = renamed[r];
    }
    return ins;
  };
  for (size_t i = 0; i < p.code.size(); ++i) {
    if (p.code[i].op != Op::LoopBegin) {
      renamed[i] = static_cast<uint32_t>(code.size());
      code.push_back(rename(p.code[i]));
      continue;
    }
    size_t end = i + 1;
    while (p.code[end].op != Op::LoopEnd) ++end;
    std::unordered_map<uint32_t, uint32_t> hoisted;  // pool index -> new register
    for (size_t j = i + 1; j < end; ++j)
      if (p.code[j].op == Op::LoadConst) {
        auto [at, fresh] = hoisted.try_emplace(p.code[j].imm, static_cast<uint32_t>(code.size()));
        if (fresh) code.push_back(p.code[j]);
        renamed[j] = at->second;
      }
    for (size_t j = i; j <= end; ++j) {
      if (j > i && j < end && p.code[j].op == Op::LoadConst) continue;
      renamed[j] = static_cast<uint32_t>(code.size());
      code.push_back(rename(p.code[j]));
    }
    i = end;
  }
  p.code = std::move(code);
}

uint64_t executedInstructions(const Program& p) {
  uint64_t total = 0, body = 0;
  bool inBody = false;
  for (const Instr& ins : p.code) {
    if (ins.op == Op::LoopBegin) inBody = true, body = 0;
    if (ins.op == Op::LoopEnd) inBody = false, total += body * p.loops[ins.imm].count;
    if (inBody && ins.op != Op::LoopBegin) ++body;
    else ++total;
  }
  return total;
}

}  // namespace qdot::kernel
