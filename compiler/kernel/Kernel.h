// The kernel IR: backend-neutral programs computing what the model ABI asks for (parameters, start
// values, residual F, Jacobian dF/dy + cj*dF/dy', outputs, invariants) from a dae::Dae.
// Instructions are in SSA form over virtual registers and use the one opcode list of
// runtime/include/qdot/opcodes.def; every instruction names the equation (source) it serves.
// Straight-line code except for loops (qdot/loop.hpp): `loop` … `endloop` runs its body once per
// element of an index range, so repeated structure costs code once, not once per element.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "dae/Dae.h"
#include "qdot/loop.hpp"
#include "qdot/model_description.hpp"
#include "qdot/programs.hpp"
#include "support/SourceManager.h"
#include "symbolic/Expr.h"

namespace qdot {
class DiagnosticEngine;
}  // namespace qdot

namespace qdot::kernel {

/// The opcodes of qdot/opcodes.def (the same numbering as qdot::bc::Opcode).
enum class Op : uint8_t {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) Name,
#include "qdot/opcodes.def"
};
/// The opcode's spelling in qdot/opcodes.def ("add", "ldy", ...).
const char* mnemonic(Op op);
/// How many of the operands a, b, c the opcode reads (its format's arity, qdot/bytecode.h).
uint32_t readCount(Op op);

/// A loop of a program: iterations c = 0 .. count-1; at iteration c the loop offset L is
/// first + c*stride if offsetTable == kNoTable, else indexTable[offsetTable + c] (qdot/loop.hpp,
/// shared with the bytecode).
using qdot::Loop;

/// One instruction. Instruction i of a program defines virtual register %i (SSA); stores, loop
/// control and `Ret` define nothing. Operands a, b, c are earlier registers; `imm` is the input
/// index for loads (ldyl, ldypl, ldpl: added to L), the constant-pool index for `ldk`, the exponent
/// (int32 bits) for `powi`, the output slot for `st` (stl: added to L), the index table position
/// for `stx` (out[indexTable[imm + c]]), the loop id for `loop` and `endloop`. A register defined
/// inside a loop body holds that iteration's value: it is read only inside the same body.
struct Instr {
  Op op = Op::Ret;
  uint32_t a = 0, b = 0, c = 0;
  uint32_t imm = 0;
  uint32_t source = UINT32_MAX;  ///< index into KernelModule::sources (UINT32_MAX: none)
};

/// A program writing out[0, outputCount): straight-line code and loops that do not nest.
struct Program {
  std::string name;
  std::vector<Instr> code;
  std::vector<double> constants;  ///< the pool `ldk` reads (distinct bit patterns)
  uint32_t outputCount = 0;
  std::vector<Loop> loops;            ///< by loop id
  std::vector<uint32_t> indexTable;   ///< X: offsets of table loops, output slots of `stx`
};

/// What an instruction serves: an equation, an output, a parameter binding, a start value ...
struct Source {
  std::string label;  ///< "equation 3 (Euler-Lagrange equation of x)"
  SourceRange range;  ///< where it is written (may be invalid)
  std::string text;   ///< the equation as written, shortened ("" if none)
};

/// Everything a backend needs to implement the model ABI.
struct KernelModule {
  SharedDescription description;  ///< names, flags, Jacobian pattern (shared by every backend)
  /// parameters: out[i] = p_i. initialValues: out = [y0 (n), yp0 (n), nominal (n)].
  /// residual: out = F (n). jacobian: out = values in CSC order. outputs, invariants: one each.
  PerProgram<Program> programs;
  std::vector<Source> sources;
  size_t sharedTemporaries = 0;  ///< CSE temporaries of residual + Jacobian together

  Program& program(ModelProgram p) { return programs[programIndex(p)]; }
  const Program& program(ModelProgram p) const { return programs[programIndex(p)]; }
  size_t variableCount() const { return description->variableCount(); }
};

/// Builds every program of the model. `ctx` must be the Context the Dae's expressions live in
/// (differentiation and CSE create nodes and the symbols `$cj` and `$t<k>`). What the programs
/// cannot compute (an implicit initial equation, a value used where it is not available) is
/// reported to `diags` at the equation or declaration concerned, and that value becomes NaN; the
/// module is complete otherwise, so a caller must check `diags.hasErrors()` before running it.
KernelModule buildKernels(const dae::Dae& dae, sym::Context& ctx, DiagnosticEngine& diags);

/// `--emit=kernel`: deterministic text of the module. With a SourceManager, sources show file:line.
void printKernels(std::ostream& os, const KernelModule& m, const SourceManager* sm = nullptr);
/// One program (used by printKernels).
void printProgram(std::ostream& os, const Program& p, const KernelModule& m);

/// "file.qd:12" for a range, "" if it has no location.
std::string describeLocation(const SourceManager& sm, SourceRange r);

/// What breaks the loop rules in `p` (loop structure, indices looped instructions reach at their
/// loop's smallest and largest offsets, operands that are not earlier registers or are defined in
/// another loop's body), "" if nothing. `variableCount`: the length of y and y'; `parameterCount`:
/// of p (ldpl).
std::string checkLoops(const Program& p, size_t variableCount, size_t parameterCount);

/// Moves the constant loads (`ldk`) of every loop body before its `loop`, one per constant: a body
/// runs them once instead of once per iteration (the JIT folds them anyway; the VM does not).
/// Registers are renumbered; what the program computes is unchanged.
void hoistLoopConstants(Program& p);

/// Instructions one run of `p` executes: a loop body's count times, the rest once.
uint64_t executedInstructions(const Program& p);

/// Reference interpreter of the kernel IR (tests and debugging; the VM is the fast path).
/// out.size() must be >= p.outputCount.
void interpret(const Program& p, const ModelCall& in, std::span<double> out);

}  // namespace qdot::kernel
