// The kernel IR: backend-neutral straight-line programs computing what the model ABI asks for
// (parameters, start values, residual F, Jacobian dF/dy + cj*dF/dy', outputs, invariants) from a
// dae::Dae. Instructions are in SSA form over virtual registers and use the one opcode list of
// runtime/include/qdot/opcodes.def; every instruction names the equation (source) it serves.
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "dae/Dae.h"
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

/// One instruction. Instruction i of a program defines virtual register %i (SSA); `Store` and
/// `Ret` define nothing. Operands a, b, c are earlier registers; `imm` is the input index for loads,
/// the constant-pool index for `ldk`, the exponent (int32 bits) for `powi`, the output slot for `st`.
struct Instr {
  Op op = Op::Ret;
  uint32_t a = 0, b = 0, c = 0;
  uint32_t imm = 0;
  uint32_t source = UINT32_MAX;  ///< index into KernelModule::sources (UINT32_MAX: none)
};

/// A straight-line program writing out[0, outputCount).
struct Program {
  std::string name;
  std::vector<Instr> code;
  std::vector<double> constants;  ///< the pool `ldk` reads (distinct bit patterns)
  uint32_t outputCount = 0;
};

/// What an instruction serves: an equation, an output, a parameter binding, a start value ...
struct Source {
  std::string label;  ///< "equation 3 (Euler-Lagrange equation of x)"
  SourceRange range;  ///< where it is written (may be invalid)
  std::string text;   ///< the equation as written, shortened ("" if none)
};

/// The programs of a module, in model-ABI order (the same order as qdot::bc::FunctionId).
enum class ProgramId : uint8_t { Parameters, InitialValues, Residual, Jacobian, Outputs, Invariants };
inline constexpr size_t kProgramCount = 6;

/// Everything a backend needs to implement the model ABI.
struct KernelModule {
  std::string name;
  std::vector<std::string> variableNames, parameterNames, parameterDescriptions, outputNames, invariantNames;
  std::vector<int32_t> isDifferential;  ///< [nVariables]
  std::vector<int32_t> fixed;           ///< [nVariables]
  std::vector<int32_t> jacobianColumnStarts, jacobianRowIndices;  ///< CSC; column j = variable j
  /// parameters: out[i] = p_i. initialValues: out = [y0 (n), yp0 (n), nominal (n)].
  /// residual: out = F (n). jacobian: out = values in CSC order. outputs, invariants: one each.
  std::array<Program, kProgramCount> programs;
  std::vector<Source> sources;
  size_t sharedTemporaries = 0;  ///< CSE temporaries of residual + Jacobian together

  Program& program(ProgramId id) { return programs[static_cast<uint8_t>(id)]; }
  const Program& program(ProgramId id) const { return programs[static_cast<uint8_t>(id)]; }
  size_t variableCount() const { return variableNames.size(); }
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

/// The inputs a program may read (unused ones may be empty).
struct Inputs {
  double t = 0, cj = 0;
  std::span<const double> y, yp, p, given;
  std::span<const uint8_t> overridden;
};

/// Reference interpreter of the kernel IR (tests and debugging; the VM is the fast path).
/// out.size() must be >= p.outputCount.
void interpret(const Program& p, const Inputs& in, std::span<double> out);

}  // namespace qdot::kernel
