// qdot bytecode: the plain data a compiled model is to the VM — per ABI function a register
// program (opcode words from qdot/opcodes.def, a constant pool, an instruction → source table),
// plus the model's names, sizes and CSC Jacobian pattern. Written by the compiler
// (compiler/bytecode), run by runtime/vm, and serialisable so executables can embed it.
#ifndef QDOT_BYTECODE_H
#define QDOT_BYTECODE_H

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace qdot::bc {

/// Every opcode, in qdot/opcodes.def order.
enum class Opcode : uint8_t {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) Name,
#include "qdot/opcodes.def"
};

/// Operand layout of an instruction (see the table at the top of qdot/opcodes.def).
enum class Format : uint8_t { End, None, Index, Unary, Binary, Ternary, UnaryIndex, Store };

/// What the disassembler and the validator need to know about an opcode.
struct OpcodeInfo {
  const char* mnemonic;
  Format format;
};

/// Indexed by Opcode.
inline constexpr OpcodeInfo kOpcodes[] = {
#define QDOT_OPCODE(Name, Mnemonic, Fmt, Value) {Mnemonic, Format::Fmt},
#include "qdot/opcodes.def"
};
inline constexpr uint32_t kOpcodeCount = sizeof(kOpcodes) / sizeof(kOpcodes[0]);

/// The table entry of op.
inline const OpcodeInfo& info(Opcode op) { return kOpcodes[static_cast<uint8_t>(op)]; }

/// Number of u32 operand words after the opcode word.
inline constexpr uint32_t operandCount(Format f) {
  constexpr uint32_t counts[] = {0, 1, 2, 2, 3, 4, 3, 2};
  return counts[static_cast<uint8_t>(f)];
}

/// The opcode spelled `mnemonic`; false if there is none.
inline bool opcodeFromMnemonic(std::string_view mnemonic, Opcode& op) {
  for (uint32_t i = 0; i < kOpcodeCount; ++i)
    if (mnemonic == kOpcodes[i].mnemonic) {
      op = static_cast<Opcode>(i);
      return true;
    }
  return false;
}

/// x^n by repeated squaring (the `powi` opcode); n < 0 gives 1 / x^-n.
inline double powi(double x, int32_t n) {
  uint32_t m = n < 0 ? 0u - static_cast<uint32_t>(n) : static_cast<uint32_t>(n);
  double r = 1.0, b = x;
  while (m) {
    if (m & 1u) r *= b;
    m >>= 1;
    if (m) b *= b;
  }
  return n < 0 ? 1.0 / r : r;
}

/// sign(x): 1, -1, 0 for 0, NaN for NaN (as compiler/symbolic evaluates it).
inline double sign(double x) { return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : (x == 0.0 ? 0.0 : x)); }

/// The functions of the model ABI that are programs (fixedStarts is a table, not a program).
enum class FunctionId : uint8_t { Parameters, InitialValues, Residual, Jacobian, Outputs, Invariants };
inline constexpr uint32_t kFunctionCount = 6;
inline constexpr const char* kFunctionNames[kFunctionCount] = {"parameters", "initialValues", "residual",
                                                               "jacobian",   "outputs",       "invariants"};

/// Function::sources entry of an instruction that serves no particular source.
inline constexpr uint32_t kNoSource = UINT32_MAX;

/// One straight-line register program. Registers [0, constants.size()) hold the constant pool
/// (loaded once, never written); the rest are scratch. Code is a sequence of instructions, each an
/// opcode word (value < 256) followed by operandCount(format) operand words; the last is `ret`.
struct Function {
  uint32_t registerCount = 0;
  uint32_t outputCount = 0;       ///< number of out[] slots the stores write
  std::vector<double> constants;  ///< the pool (also addressable with `ldk`)
  std::vector<uint32_t> code;
  std::vector<uint32_t> sources;  ///< per instruction (in order): index into Module::locations, or kNoSource
};

/// Where an instruction comes from, for error messages: "<label> at <where>".
struct Location {
  std::string label;  ///< "equation 3 (Euler-Lagrange equation of x)", "output E", "parameter k"
  std::string where;  ///< "model.qd:12" ("" if unknown)
  std::string text;   ///< the equation as written, possibly shortened ("" if none)
};

/// Version of the serialised form; deserialize refuses any other.
inline constexpr uint32_t kFormatVersion = 1;

/// A whole model. Sizes are the lengths of the name vectors.
struct Module {
  std::string name;
  std::vector<std::string> variableNames, parameterNames, parameterDescriptions, outputNames, invariantNames;
  std::vector<int32_t> isDifferential;  ///< [nVariables]
  std::vector<int32_t> fixed;           ///< [nVariables]: start value fixed during initialisation
  std::vector<int32_t> jacobianColumnStarts, jacobianRowIndices;  ///< CSC, column j = variable j
  std::array<Function, kFunctionCount> functions;
  std::vector<Location> locations;

  Function& function(FunctionId id) { return functions[static_cast<uint8_t>(id)]; }
  const Function& function(FunctionId id) const { return functions[static_cast<uint8_t>(id)]; }
};

// Implemented in runtime/vm (qdot_vm).

/// Little-endian bytes: magic "QDBC", kFormatVersion, then every field in declaration order.
std::vector<uint8_t> serialize(const Module& m);
/// Reads bytes written by serialize and validates them; false (with `error`) if malformed.
bool deserialize(std::span<const uint8_t> bytes, Module& m, std::string& error);
/// Checks everything the VM relies on (opcodes, operand ranges, loads allowed per function,
/// constant registers never written, sizes consistent); false with `error` naming the first problem.
bool validate(const Module& m, std::string& error);

}  // namespace qdot::bc

#endif  // QDOT_BYTECODE_H
