// `--emit=kernel`: the module header (names, flags, Jacobian pattern) and each program, one
// instruction per line, with the source an instruction serves shown when it changes.
#include <ostream>

#include "kernel/Kernel.h"
#include "qdot/bytecode.h"
#include "qdot/number_text.hpp"

namespace qdot::kernel {
namespace {

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

const std::vector<std::string>* namesOfLoad(Op op, const KernelModule& m) {
  switch (op) {
    case Op::LoadY:
    case Op::LoadYp: return &m.description->variableNames;
    case Op::LoadP:
    case Op::LoadGiven:
    case Op::LoadOverridden: return &m.description->parameterNames;
    default: return nullptr;
  }
}

std::string operands(const Instr& ins, const Program& prog, const KernelModule& m) {
  auto reg = [](uint32_t r) { return std::string("%").append(std::to_string(r)); };
  switch (bc::info(static_cast<bc::Opcode>(ins.op)).format) {
    case bc::Format::End:
    case bc::Format::None: return "";
    case bc::Format::Index: {
      if (ins.op == Op::LoadConst) return shortestText(prog.constants[ins.imm]);
      if (ins.op == Op::LoadYLooped || ins.op == Op::LoadYpLooped || ins.op == Op::LoadPLooped)
        return std::to_string(ins.imm) + " + L";
      const auto* names = namesOfLoad(ins.op, m);
      return std::to_string(ins.imm) + (names && ins.imm < names->size() ? std::string(" (").append((*names)[ins.imm]) + ")" : "");
    }
    case bc::Format::Unary: return reg(ins.a);
    case bc::Format::Binary: return reg(ins.a) + ", " + reg(ins.b);
    case bc::Format::Ternary: return reg(ins.a) + ", " + reg(ins.b) + ", " + reg(ins.c);
    case bc::Format::UnaryIndex: return reg(ins.a) + ", " + std::to_string(static_cast<int32_t>(ins.imm));
    case bc::Format::Store:
    case bc::Format::StoreAdd: return std::string("out[").append(std::to_string(ins.imm)) + "], " + reg(ins.a);
    case bc::Format::StoreLooped: return std::string("out[").append(std::to_string(ins.imm)) + " + L], " + reg(ins.a);
    case bc::Format::StoreIndexed: return std::string("out[X[").append(std::to_string(ins.imm)) + " + c]], " + reg(ins.a);
    case bc::Format::LoopBegin:
      return std::to_string(ins.imm) + (ins.imm < prog.loops.size() ? " (" + loopText(prog.loops[ins.imm]) + ")" : "");
    case bc::Format::LoopEnd: return std::to_string(ins.imm);
  }
  return "";
}

void printHeader(std::ostream& os, const KernelModule& m) {
  const ModelDescription& d = m.description;
  os << "kernel " << d.name << "\n";
  os << "variables (" << m.variableCount() << "):";
  for (size_t j = 0; j < m.variableCount(); ++j)
    os << (j ? ", " : " ") << d.variableNames[j] << (d.isDifferential[j] ? " [differential" : " [algebraic")
       << (d.fixed[j] ? ", fixed]" : "]");
  os << "\nparameters (" << d.parameterNames.size() << "): " << join(d.parameterNames) << "\n";
  os << "outputs (" << d.outputNames.size() << "): " << join(d.outputNames) << "\n";
  os << "invariants (" << d.invariantNames.size() << "): " << join(d.invariantNames) << "\n";
  os << "jacobian (CSC, " << d.jacobianRowIndices.size() << " nonzeros, " << m.sharedTemporaries
     << " CSE temporaries shared with the residual):\n";
  for (size_t j = 0; j < m.variableCount(); ++j) {
    os << "  column " << j << " (" << d.variableNames[j] << "): rows";
    for (int32_t k = d.jacobianColumnStarts[j]; k < d.jacobianColumnStarts[j + 1]; ++k)
      os << " " << d.jacobianRowIndices[k];
    os << "\n";
  }
}

}  // namespace

const char* mnemonic(Op op) { return bc::info(static_cast<bc::Opcode>(op)).mnemonic; }
uint32_t readCount(Op op) { return bc::readCount(bc::info(static_cast<bc::Opcode>(op)).format); }

std::string describeLocation(const SourceManager& sm, SourceRange r) {
  if (!r.valid()) return "";
  return sm.name(r.file) + ":" + std::to_string(sm.lineCol(r.file, r.begin).line);
}

void printProgram(std::ostream& os, const Program& prog, const KernelModule& m) {
  os << "\nfunction " << prog.name << ": " << prog.outputCount << " outputs, " << prog.code.size()
     << " instructions, " << prog.constants.size() << " constants";
  if (!prog.loops.empty()) os << ", " << prog.loops.size() << " loops (" << executedInstructions(prog) << " instructions per run)";
  os << "\n";
  if (!prog.indexTable.empty()) os << "  X =";
  for (uint32_t x : prog.indexTable) os << " " << x;
  if (!prog.indexTable.empty()) os << "\n";
  uint32_t source = UINT32_MAX - 1;
  const char* indent = "  ";  // deeper inside a loop body
  for (size_t i = 0; i < prog.code.size(); ++i) {
    const Instr& ins = prog.code[i];
    if (ins.source != source && ins.source < m.sources.size()) os << indent << "; " << m.sources[ins.source].label << "\n";
    source = ins.source;
    bool defines = bc::definesRegister(bc::info(static_cast<bc::Opcode>(ins.op)).format);
    std::string lhs = defines ? std::string("%").append(std::to_string(i)) + " = " : "";
    std::string ops = operands(ins, prog, m);
    if (ins.op == Op::LoopEnd) indent = "  ";
    os << indent << lhs << mnemonic(ins.op) << (ops.empty() ? "" : " " + ops) << "\n";
    if (ins.op == Op::LoopBegin) indent = "    ";
  }
}

void printKernels(std::ostream& os, const KernelModule& m, const SourceManager* sm) {
  printHeader(os, m);
  if (sm) {
    os << "sources:\n";
    for (size_t s = 0; s < m.sources.size(); ++s) {
      std::string where = describeLocation(*sm, m.sources[s].range);
      os << "  " << m.sources[s].label << (where.empty() ? "" : " at " + where)
         << (m.sources[s].text.empty() ? "" : ": " + m.sources[s].text) << "\n";
    }
  }
  for (const Program& p : m.programs) printProgram(os, p, m);
}

}  // namespace qdot::kernel
