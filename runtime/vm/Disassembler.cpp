// The disassembler (`qdot ... --emit=bytecode`): every function's constants and instructions,
// one per line with its word offset, and the source an instruction serves whenever it changes.
// Driven by the opcode table, so a new opcode is printed without touching this file.
#include <algorithm>
#include <cstdio>
#include <ostream>

#include "vm/Vm.h"
#include "qdot/number_text.hpp"

namespace qdot::vm {
namespace {

std::string reg(uint32_t r) { return std::string("r").append(std::to_string(r)); }

std::string indexName(const bc::Module& m, bc::Opcode op, uint32_t i, const bc::Function& f) {
  const std::vector<std::string>* names = nullptr;
  if (op == bc::Opcode::LoadY || op == bc::Opcode::LoadYp) names = &m.description->variableNames;
  if (op == bc::Opcode::LoadP || op == bc::Opcode::LoadGiven || op == bc::Opcode::LoadOverridden)
    names = &m.description->parameterNames;
  if (op == bc::Opcode::LoadConst && i < f.constants.size()) return std::to_string(i) + std::string(" (").append(shortestText(f.constants[i])) + ")";
  if (op == bc::Opcode::LoadYLooped || op == bc::Opcode::LoadYpLooped || op == bc::Opcode::LoadPLooped)
    return std::to_string(i) + " + L";
  return std::to_string(i) + (names && i < names->size() ? std::string(" (").append((*names)[i]) + ")" : "");
}

std::string operandText(const bc::Module& m, const bc::Function& f, const uint32_t* ip) {
  auto op = static_cast<bc::Opcode>(*ip);
  const uint32_t* o = ip + 1;
  switch (bc::info(op).format) {
    case bc::Format::End: return "";
    case bc::Format::None: return reg(o[0]);
    case bc::Format::Index: return reg(o[0]) + ", " + indexName(m, op, o[1], f);
    case bc::Format::Unary: return reg(o[0]) + ", " + reg(o[1]);
    case bc::Format::Binary: return reg(o[0]) + ", " + reg(o[1]) + ", " + reg(o[2]);
    case bc::Format::Ternary: return reg(o[0]) + ", " + reg(o[1]) + ", " + reg(o[2]) + ", " + reg(o[3]);
    case bc::Format::UnaryIndex: return reg(o[0]) + ", " + reg(o[1]) + ", " + std::to_string(static_cast<int32_t>(o[2]));
    case bc::Format::Store:
    case bc::Format::StoreAdd: return std::string("out[").append(std::to_string(o[0])) + "], " + reg(o[1]);
    case bc::Format::StoreLooped: return std::string("out[").append(std::to_string(o[0])) + " + L], " + reg(o[1]);
    case bc::Format::StoreIndexed: return std::string("out[X[").append(std::to_string(o[0])) + " + c]], " + reg(o[1]);
    case bc::Format::LoopBegin: {
      std::string exit = "exit " + std::to_string(ip - f.code.data() + o[1]);
      return std::to_string(o[0]) + " (" + (o[0] < f.loops.size() ? loopText(f.loops[o[0]]) + ", " : "") + exit + ")";
    }
    case bc::Format::LoopEnd: return std::to_string(o[0]);
  }
  return "";
}

void printSource(std::ostream& os, const bc::Module& m, uint32_t loc) {
  if (loc >= m.locations.size()) return;
  const bc::Location& l = m.locations[loc];
  os << "  ; " << l.label << (l.where.empty() ? "" : " at " + l.where) << (l.text.empty() ? "" : ": " + l.text)
     << "\n";
}

}  // namespace

void disassembleFunction(std::ostream& os, const bc::Module& m, ModelProgram program) {
  const bc::Function& f = m.function(program);
  size_t instructions = f.sources.size();
  os << "\nfunction " << programName(program) << ": " << f.registerCount << " registers ("
     << f.constants.size() << " constants), " << f.outputCount << " outputs, " << instructions << " instructions, "
     << f.code.size() << " words\n";
  for (size_t k = 0; k < f.constants.size(); ++k) os << "  " << reg(k) << " = " << shortestText(f.constants[k]) << "\n";
  if (!f.indexTable.empty()) os << "  X =";
  for (uint32_t x : f.indexTable) os << " " << x;
  if (!f.indexTable.empty()) os << "\n";
  uint32_t source = bc::kNoSource - 1;
  size_t ordinal = 0;
  bool inLoop = false;  // indents loop bodies
  for (size_t pc = 0; pc < f.code.size() && f.code[pc] < bc::kOpcodeCount; ++ordinal) {
    const uint32_t* ip = &f.code[pc];
    uint32_t loc = ordinal < f.sources.size() ? f.sources[ordinal] : bc::kNoSource;
    if (loc != source) printSource(os, m, loc);
    source = loc;
    const bc::OpcodeInfo& info = bc::info(static_cast<bc::Opcode>(*ip));
    char offset[16];
    std::snprintf(offset, sizeof offset, "%04zu", pc);
    std::string ops = operandText(m, f, ip), name = info.mnemonic;
    if (!ops.empty()) name.resize(std::max<size_t>(name.size() + 1, 8), ' ');
    if (info.format == bc::Format::LoopEnd) inLoop = false;
    os << "  " << offset << (inLoop ? "    " : "  ") << name << ops << "\n";
    if (info.format == bc::Format::LoopBegin) inLoop = true;
    pc += 1 + bc::operandCount(info.format);
  }
}

void disassemble(std::ostream& os, const bc::Module& m) {
  const ModelDescription& d = m.description;
  os << "bytecode " << d.name << " (format " << bc::kFormatVersion << "): " << d.variableNames.size()
     << " variables, " << d.parameterNames.size() << " parameters, " << d.outputNames.size() << " outputs, "
     << d.invariantNames.size() << " invariants, " << d.jacobianRowIndices.size() << " Jacobian nonzeros\n";
  for (size_t f = 0; f < kModelProgramCount; ++f) disassembleFunction(os, m, programAt(f));
}

}  // namespace qdot::vm
