// diagnoseNonFinite: why a program produced a non-finite output, in words. The program is re-run
// one instruction at a time with the opcodes.def expressions, tracking for each register the
// instruction where the non-finite value it carries first arose from finite operands. Only the
// operands a result depends on count (for a select: the condition and the branch taken), so a
// NaN in an untaken branch is never blamed; a non-finite constant (e.g. a parameter without a
// value) makes a value "undefined". The one diagnosis of both backends: the VM decodes its
// bytecode into a ProgramTrace, the LLVM backend its kernel IR. Header-only so that neither
// backend links the other (it runs only after a failure; speed does not matter). Loops run as the
// VM runs them; a value going wrong inside one is named with its iteration and loop offset.
#pragma once

#include <cmath>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "qdot/bytecode.h"
#include "qdot/model_description.hpp"
#include "qdot/number_text.hpp"
#include "qdot/programs.hpp"

namespace qdot {

/// A program as the diagnosis reads it.
struct ProgramTrace {
  std::vector<bc::Instruction> code;  ///< in order; a `ret` ends it
  std::vector<uint32_t> sources;      ///< per instruction: index into the locations, or bc::kNoSource
  std::span<const double> constants;  ///< the pool `ldk` reads
  uint32_t preloaded = 0;             ///< registers [0, preloaded) start as constants[0, preloaded)
  uint32_t registerCount = 0;
  std::span<const Loop> loops;           ///< by loop id
  std::span<const uint32_t> indexTable;  ///< X
};

namespace detail {

inline constexpr uint32_t kFiniteOrigin = UINT32_MAX;        // origin of a finite value
inline constexpr uint32_t kConstantOrigin = UINT32_MAX - 1;  // a non-finite constant of the pool

// Where the re-run is: the open loop (nullptr outside loops), its iteration c and offset L, and
// the ordinal of its body's first instruction.
struct LoopPosition {
  const Loop* loop = nullptr;
  uint32_t c = 0;
  int64_t L = 0;
  uint32_t body = 0;
};

// The ordinal of the instruction to run after loop control instruction `i` (`loop`, `endloop`).
inline uint32_t stepLoop(const ProgramTrace& trace, uint32_t i, LoopPosition& at) {
  if (trace.code[i].op == bc::Opcode::LoopBegin) {
    at = {&trace.loops[trace.code[i].imm], 0, 0, i + 1};
  } else if (++at.c == at.loop->count) {
    at.loop = nullptr;
    return i + 1;
  }
  if (at.loop->count == 0) {  // no iteration: past its endloop
    while (trace.code[i].op != bc::Opcode::LoopEnd) ++i;
    at.loop = nullptr;
    return i + 1;
  }
  at.L = at.loop->offset(at.c, trace.indexTable.data());
  return at.body;
}

// The value `ins` computes (a store: the value stored).
inline double evaluate(const bc::Instruction& ins, const std::vector<double>& r, const ModelCall& in, const double* k,
                       const LoopPosition& at, const uint32_t* X) {
  [[maybe_unused]] const uint32_t c = at.c;
  [[maybe_unused]] const int64_t L = at.L;
  [[maybe_unused]] const double t = in.t, cj = in.cj;
  [[maybe_unused]] const double *y = in.y, *yp = in.yp, *p = in.p, *given = in.given;
  [[maybe_unused]] const uint8_t* overridden = in.overridden;
  [[maybe_unused]] const double A = r[ins.a], B = r[ins.b], C = r[ins.c];
  [[maybe_unused]] const uint32_t I = ins.imm;
  switch (ins.op) {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) \
  case bc::Opcode::Name: return (Value);
#include "qdot/opcodes.def"
  }
  return 0.0;
}

// The registers the result of `ins` depends on.
inline uint32_t dependencies(const bc::Instruction& ins, const std::vector<double>& r, uint32_t deps[3]) {
  deps[0] = ins.a, deps[1] = ins.b, deps[2] = ins.c;
  if (ins.op != bc::Opcode::Select) return bc::readCount(bc::info(ins.op).format);
  deps[1] = r[ins.a] != 0.0 ? ins.b : ins.c;
  return 2;
}

inline std::string nameAt(const std::vector<std::string>& names, uint32_t i) { return i < names.size() ? names[i] : "?"; }

// Why `ins` produced a non-finite value from finite operands A, B (or from nothing, for loads).
inline std::string describeProblem(const ModelDescription& d, const bc::Instruction& ins, double A, double B,
                                   double value, int64_t L) {
  const std::string a = shortestText(A), b = shortestText(B), v = shortestText(value);
  const auto looped = static_cast<uint32_t>(ins.imm + L);
  switch (ins.op) {
    case bc::Opcode::Sqrt: return "sqrt of a negative number (" + a + ")";
    case bc::Opcode::Log: return A == 0.0 ? "log of zero" : "log of a negative number (" + a + ")";
    case bc::Opcode::Asin:
    case bc::Opcode::Acos: return std::string(bc::info(ins.op).mnemonic) + " of a number outside [-1, 1] (" + a + ")";
    case bc::Opcode::Div: return B == 0.0 ? "division by zero (" + a + "/0)" : "overflow in " + a + "/" + b;
    case bc::Opcode::Pow:
      if (A < 0.0 && B != std::trunc(B)) return "power of a negative number (" + a + "^" + b + ")";
      return A == 0.0 ? "zero to a negative power (0^" + b + ")" : "overflow in " + a + "^" + b;
    case bc::Opcode::Powi: {
      std::string e = std::to_string(static_cast<int32_t>(ins.imm));
      return A == 0.0 ? "zero to a negative power (0^" + e + ")" : "overflow in " + a + "^" + e;
    }
    case bc::Opcode::LoadY: return "the value of " + nameAt(d.variableNames, ins.imm) + " is " + v;
    case bc::Opcode::LoadYp: return "the value of der(" + nameAt(d.variableNames, ins.imm) + ") is " + v;
    case bc::Opcode::LoadYLooped: return "the value of " + nameAt(d.variableNames, looped) + " is " + v;
    case bc::Opcode::LoadYpLooped: return "the value of der(" + nameAt(d.variableNames, looped) + ") is " + v;
    case bc::Opcode::LoadPLooped: return "parameter " + nameAt(d.parameterNames, looped) + " is " + v;
    case bc::Opcode::LoadP: return "parameter " + nameAt(d.parameterNames, ins.imm) + " is " + v;
    case bc::Opcode::LoadGiven: return "the value given for parameter " + nameAt(d.parameterNames, ins.imm) + " is " + v;
    case bc::Opcode::LoadTime: return "time is " + v;
    case bc::Opcode::LoadCj: return "cj is " + v;
    default: break;
  }
  return "overflow in " + std::string(bc::info(ins.op).mnemonic) + " (" + v + ")";
}

// " in <label> at <where>" of the culprit; when the value it spoiled belongs to another source (a
// shared subexpression), that one is named too; outside the residual, the program.
inline std::string placeOf(const ProgramTrace& trace, std::span<const bc::Location> locations, uint32_t culprit,
                           uint32_t store, ModelProgram program) {
  auto label = [&](uint32_t ordinal) {
    uint32_t loc = ordinal < trace.sources.size() ? trace.sources[ordinal] : bc::kNoSource;
    if (loc >= locations.size()) return std::string();
    const bc::Location& l = locations[loc];
    return l.label + (l.where.empty() ? "" : " at " + l.where);
  };
  std::string where = label(culprit), spoiled = label(store), s;
  if (!where.empty()) s = " in " + where;
  if (!spoiled.empty() && spoiled != where) s += ", which makes " + spoiled + " non-finite";
  if (program != ModelProgram::Residual) s += std::string(" (computing ") + programName(program) + ")";
  return s;
}

}  // namespace detail

/// Re-runs `trace` (program `program` of the model described by `d`) on `in` and describes its
/// first non-finite output by the instruction the value came from, e.g. "sqrt of a negative
/// number (-0.25) in equation 3 (...) at model.qd:12", plus ", which makes <other source>
/// non-finite" for a shared value and " (computing <program>)" outside the residual. "" if
/// every output is finite.
inline std::string diagnoseNonFinite(const ModelDescription& d, std::span<const bc::Location> locations,
                                     ModelProgram program, const ProgramTrace& trace, const ModelCall& in) {
  using namespace detail;
  std::vector<double> r(trace.registerCount, 0.0);
  std::vector<uint32_t> origin(trace.registerCount, kFiniteOrigin);
  for (uint32_t i = 0; i < trace.preloaded; ++i)
    if (!std::isfinite(r[i] = trace.constants[i])) origin[i] = kConstantOrigin;
  std::unordered_map<uint32_t, std::string> problems;  // culprit ordinal -> what went wrong
  LoopPosition at;
  for (uint32_t i = 0, next = 0; i < trace.code.size(); i = next) {
    const bc::Instruction& ins = trace.code[i];
    next = i + 1;
    if (ins.op == bc::Opcode::Ret) break;
    if (ins.op == bc::Opcode::LoopBegin || ins.op == bc::Opcode::LoopEnd) {
      next = stepLoop(trace, i, at);
      continue;
    }
    uint32_t deps[3], from = kFiniteOrigin;
    bool undefined = false;  // depends on a non-finite constant
    for (uint32_t j = 0, n = dependencies(ins, r, deps); j < n; ++j) {
      if (std::isfinite(r[deps[j]])) continue;
      if (origin[deps[j]] == kConstantOrigin) undefined = true;
      else if (from == kFiniteOrigin) from = origin[deps[j]];
    }
    double value = evaluate(ins, r, in, trace.constants.data(), at, trace.indexTable.data());
    if (ins.op == bc::Opcode::LoadConst) {
      r[ins.dest] = value, origin[ins.dest] = std::isfinite(value) ? kFiniteOrigin : kConstantOrigin;
      continue;
    }
    if (!std::isfinite(value) && from == kFiniteOrigin) {
      from = i;
      problems[i] = undefined ? "undefined value (" + shortestText(value) + ")"
                              : describeProblem(d, ins, r[ins.a], r[ins.b], value, at.L);
      if (at.loop)
        problems[i] += " (loop iteration " + std::to_string(at.c) + ", offset " + std::to_string(at.L) + ")";
    }
    if (bc::isStore(bc::info(ins.op).format)) {
      if (!std::isfinite(value)) return problems[from] + placeOf(trace, locations, from, i, program);
      continue;
    }
    r[ins.dest] = value;
    origin[ins.dest] = std::isfinite(value) ? kFiniteOrigin : from;
  }
  return "";
}

}  // namespace qdot
