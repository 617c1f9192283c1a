// The LLVM backend's public interface: compiles a kernel::KernelModule to native code with LLVM's
// ORC JIT (in-process) and wraps it as a QdotModel (runtime/include/qdot/model_abi.h), the same
// ABI the bytecode VM implements. No LLVM type appears here; LLVM headers stay in compiler/llvm.
#pragma once

#include <memory>

#include <atomic>
#include <cstdint>
#include <string>

#include "kernel/Kernel.h"
#include "qdot/model_abi.h"
#include "qdot/programs.hpp"
#include "qdot/result.hpp"
#include "support/SourceManager.h"

namespace qdot::llvmbackend {

/// See JitOptions::compileRunOnceFrom.
inline constexpr uint64_t kRunOnceRepeats = 100;

/// Bit of `program` in JitOptions::compiledPrograms.
constexpr uint32_t programBit(ModelProgram program) { return 1u << programIndex(program); }
/// Every program (tests compile all six, each at one level, to check every lowering).
constexpr uint32_t kAllPrograms = (1u << kModelProgramCount) - 1;

/// How to compile.
struct JitOptions {
  /// Code generator level 0-3 of the residual, the program IDA calls most (0: fast instruction
  /// selection and register allocation; 2: about 1.8x faster code, 4-5x the compile time).
  int optLevel = 2;
  /// Level of the Jacobian; -1 = optLevel. Default 0: IDA evaluates it 20-250x less often than the
  /// residual (nlink n = 8: 80 against 1 612 calls in 10 s; chain n = 1 000: 20 against 5 336), so
  /// O2's faster code (0.56 against 1.46 us on nlink 8) repays its compile time (~20 ms) only after
  /// thousands of simulated seconds; on store-bound Jacobians (the chain) O2 gains nothing.
  int jacobianOptLevel = 0;
  /// Level of the other compiled programs (outputs, invariants: once per output row).
  int coldOptLevel = 0;
  /// Programs longer than this (kernel instructions) are split into several LLVM functions so
  /// that compile time stays linear in the program size (LLVM is super-linear on huge blocks).
  uint32_t maxInstructionsPerFunction = 500;
  /// Level of the new-pass-manager IR pipeline (buildPerModuleDefaultPipeline), -1 = optLevel.
  /// Default 0 (none): the kernel IR is already CSE'd straight-line code, and measured, O2's
  /// pipeline costs compile time without making the code faster (README.md).
  int pipelineLevel = 0;
  /// Models with more kernel instructions than this are code-generated at level 0 whatever
  /// optLevel says (compile time ~20x lower, code ~15% slower on the chain; README.md).
  size_t largeModelInstructions = 200000;
  /// Programs compiled to machine code (programBit); the others run on the kernel interpreter.
  /// Default: all but parameters and start values, which run once per simulation.
  uint32_t compiledPrograms = programBit(ModelProgram::Residual) | programBit(ModelProgram::Jacobian) |
                              programBit(ModelProgram::Outputs) | programBit(ModelProgram::Invariants);
  /// ... except that a program that runs once is compiled too when one run of it executes at least
  /// this many kernel instructions (kernel::executedInstructions) and kRunOnceRepeats times its
  /// length: a large model's start values in loops. At 10⁶ masses the interpreter spent 60–75 ms of
  /// IDA's setup on them (9·10⁶ instructions, ~7 ns each); their loop program of 18 instructions
  /// compiles in about a millisecond. Straight-line code (a run executes each instruction once)
  /// stays interpreted: level 0 costs ~0.4 µs per instruction, 60 times the interpreter's.
  uint64_t compileRunOnceFrom = 1000000;
  /// Compile threads; 0 = one per hardware thread (at most 8).
  unsigned threads = 0;
  /// Run LLVM's IR verifier on every module (the tests do; it costs ~60% of lowering, and the
  /// lowering is the same code for every model).
  bool verifyIR = false;
  /// If set and it becomes true, compiling stops at the next unit and fails ("cancelled"): the run
  /// that wanted the code is over (rt::TieredModel).
  const std::atomic<bool>* cancel = nullptr;
};

/// What compiling cost, and how the programs were split (for tests and measurements).
struct JitStats {
  double lowerSeconds = 0;     ///< kernel IR -> LLVM IR (summed over threads)
  double optimiseSeconds = 0;  ///< the optimisation pipeline (summed over threads)
  double codegenSeconds = 0;   ///< machine code generation (summed over threads)
  double linkSeconds = 0;      ///< creating the JIT, linking the objects, looking up the entries
  double wallSeconds = 0;      ///< the whole compile, as the user waits for it
  unsigned threads = 0;        ///< compile threads used
  unsigned units = 0;          ///< modules compiled (each part of a program is in exactly one)
  PerProgram<uint32_t> functions{};   ///< LLVM functions per program (0: interpreted)
  PerProgram<uint32_t> spillSlots{};  ///< values passed between them
};

/// Compiles every program of `k` and returns a model implementing the whole ABI, or why it cannot.
/// `sm` resolves source locations for lastError ("... in equation 3 at model.qd:9").
/// The JIT session lives inside the model; destroy() releases it. Like the VM's models, one model
/// must not be called from several threads at once (it owns scratch memory).
/// Fills `stats` if given.
Result<ModelPtr> createJitModel(const kernel::KernelModule& k, const SourceManager& sm, const JitOptions& options,
                                JitStats* stats = nullptr);
/// The same, sharing the kernels instead of copying them (a large model's tables are large).
Result<ModelPtr> createJitModel(std::shared_ptr<const kernel::KernelModule> k, const SourceManager& sm,
                                const JitOptions& options, JitStats* stats = nullptr);

/// The options for one simulation (qdot run): the defaults, without the invariants unless the run
/// asks for them.
inline JitOptions jitOptionsForRun(bool invariants) {
  JitOptions options;
  if (!invariants) options.compiledPrograms &= ~programBit(ModelProgram::Invariants);
  return options;
}

}  // namespace qdot::llvmbackend
