// qdot bytecode: the plain data a compiled model is to the VM — per model program (qdot/programs.def)
// a register program (opcode words from qdot/opcodes.def, a constant pool, an instruction → source
// table), plus the model's description (qdot/model_description.hpp: names, flags, CSC pattern). Written by the compiler
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

#include "qdot/loop.hpp"
#include "qdot/model_description.hpp"
#include "qdot/programs.hpp"
#include "qdot/result.hpp"

namespace qdot::bc {

/// Every opcode, in qdot/opcodes.def order.
enum class Opcode : uint8_t {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) Name,
#include "qdot/opcodes.def"
};

/// The instruction formats of qdot/opcodes.def: X(Name, operand words, registers read). The one
/// arity table: the encoder, the validator, the VM, the kernel IR and the diagnosis all use it.
#define QDOT_INSTRUCTION_FORMATS(X) \
  X(End, 0, 0)                      \
  X(None, 1, 0)                     \
  X(Index, 2, 0)                    \
  X(Unary, 2, 1)                    \
  X(Binary, 3, 2)                   \
  X(Ternary, 4, 3)                  \
  X(UnaryIndex, 3, 1)               \
  X(Store, 2, 1)                    \
  X(StoreLooped, 2, 1)              \
  X(StoreIndexed, 2, 1)             \
  X(StoreAdd, 2, 1)                 \
  X(LoopBegin, 2, 0)                \
  X(LoopEnd, 1, 0)

/// Operand layout of an instruction (see the table at the top of qdot/opcodes.def).
enum class Format : uint8_t {
#define QDOT_FORMAT_ENUM(Name, Words, Reads) Name,
  QDOT_INSTRUCTION_FORMATS(QDOT_FORMAT_ENUM)
#undef QDOT_FORMAT_ENUM
};

/// Number of u32 operand words after the opcode word.
inline constexpr uint32_t operandCount(Format f) {
  constexpr uint32_t words[] = {
#define QDOT_FORMAT_WORDS(Name, Words, Reads) Words,
      QDOT_INSTRUCTION_FORMATS(QDOT_FORMAT_WORDS)
#undef QDOT_FORMAT_WORDS
  };
  return words[static_cast<uint8_t>(f)];
}

/// Number of registers an instruction of format f reads (operands a, b, c in that order).
inline constexpr uint32_t readCount(Format f) {
  constexpr uint32_t reads[] = {
#define QDOT_FORMAT_READS(Name, Words, Reads) Reads,
      QDOT_INSTRUCTION_FORMATS(QDOT_FORMAT_READS)
#undef QDOT_FORMAT_READS
  };
  return reads[static_cast<uint8_t>(f)];
}

/// True for the formats writing out[] (st, stl, stx, stadd).
inline constexpr bool isStore(Format f) {
  return f == Format::Store || f == Format::StoreLooped || f == Format::StoreIndexed || f == Format::StoreAdd;
}
/// True for `loop` and `endloop`.
inline constexpr bool isLoopControl(Format f) { return f == Format::LoopBegin || f == Format::LoopEnd; }
/// True if an instruction of format f writes a register (all but End, the stores and loop control).
inline constexpr bool definesRegister(Format f) { return f != Format::End && !isStore(f) && !isLoopControl(f); }

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

/// An instruction with its operands named as in the kernel IR: `dest` the register it defines,
/// a, b, c the registers it reads, `imm` its immediate (for stores: the output slot or table
/// index; for `loop`, `endloop`: the loop id).
struct Instruction {
  Opcode op = Opcode::Ret;
  uint32_t dest = 0, a = 0, b = 0, c = 0, imm = 0;
};

/// The instruction whose opcode word is ip[0] (layout: dest, registers read, immediate; stores:
/// slot, a; `loop`: id, exit distance; `endloop`: id).
inline Instruction decode(const uint32_t* ip) {
  Instruction ins;
  ins.op = static_cast<Opcode>(ip[0]);
  Format f = info(ins.op).format;
  const uint32_t* o = ip + 1;
  if (definesRegister(f)) ins.dest = *o++;
  if (isStore(f) || isLoopControl(f)) ins.imm = *o++;
  uint32_t* reads[3] = {&ins.a, &ins.b, &ins.c};
  for (uint32_t i = 0; i < readCount(f); ++i) *reads[i] = *o++;
  if (f == Format::Index || f == Format::UnaryIndex) ins.imm = *o;
  return ins;
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

/// Function::sources entry of an instruction that serves no particular source.
inline constexpr uint32_t kNoSource = UINT32_MAX;

/// One register program: straight-line code with loops (qdot/loop.hpp). Registers
/// [0, constants.size()) hold the constant pool (loaded once, never written); the rest are scratch.
/// Code is a sequence of instructions, each an opcode word (value < 256) followed by
/// operandCount(format) operand words; the last is `ret`.
struct Function {
  uint32_t registerCount = 0;
  uint32_t outputCount = 0;       ///< number of out[] slots the stores write
  std::vector<double> constants;  ///< the pool (also addressable with `ldk`)
  std::vector<uint32_t> code;
  std::vector<uint32_t> sources;  ///< per instruction (in order): index into Module::locations, or kNoSource
  std::vector<Loop> loops;        ///< by loop id (the immediate of `loop`, `endloop`)
  std::vector<uint32_t> indexTable;  ///< X: loop offsets of table loops, output slots of `stx`
};

/// Where an instruction comes from, for error messages: "<label> at <where>".
struct Location {
  std::string label;  ///< "equation 3 (Euler-Lagrange equation of x)", "output E", "parameter k"
  std::string where;  ///< "model.qd:12" ("" if unknown)
  std::string text;   ///< the equation as written, possibly shortened ("" if none)
};

/// Version of the serialised form; deserialize refuses any other.
inline constexpr uint32_t kFormatVersion = 7;

/// A whole model: its description (names, flags, Jacobian pattern) and one function per program.
struct Module {
  SharedDescription description;  ///< shared with the kernels it was emitted from
  PerProgram<Function> functions;
  std::vector<Location> locations;

  Function& function(ModelProgram p) { return functions[programIndex(p)]; }
  const Function& function(ModelProgram p) const { return functions[programIndex(p)]; }
};

// Implemented in runtime/vm (qdot_vm).

/// Little-endian bytes: magic "QDBC", kFormatVersion, then every field in declaration order.
std::vector<uint8_t> serialize(const Module& m);
/// Reads bytes written by serialize and validates them; the error says what is malformed.
Result<Module> deserialize(std::span<const uint8_t> bytes);
/// Checks everything the VM relies on (opcodes, operand ranges, loads allowed per function,
/// constant registers never written, the description consistent); the error names the first problem.
Status validate(const Module& m);

}  // namespace qdot::bc

#endif  // QDOT_BYTECODE_H
