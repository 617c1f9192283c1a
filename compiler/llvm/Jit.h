// The ORC JIT session of one model (internal to compiler/llvm): lowers the programs of a
// KernelModule in parallel units, compiles each to an object in memory, links them in-process
// with LLJIT and hands out each program's functions.
// No LLVM type in this header, so JitModel.cpp's ABI code stays plain C++.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "llvm/JitModel.h"

namespace qdot::llvmbackend {

/// The C signature of every compiled program (see README.md): `call` holds the inputs (those a
/// program does not read may be null); out [outputCount]; spill [spill slots of the program]
/// (scratch). `out` and `spill` must not overlap the inputs.
using ProgramFn = void (*)(const ModelCall* call, double* out, double* spill);

/// Compiled code of every program; owns the LLJIT instance (and so the machine code).
class JitSession {
 public:
  /// Compiles `k`, or says why it cannot. Fills `stats` if given. The code reads k's index tables
  /// in place: `k` must outlive the session.
  static Result<std::unique_ptr<JitSession>> compile(const kernel::KernelModule& k, const JitOptions& options,
                                                     JitStats* stats);
  ~JitSession();
  JitSession(const JitSession&) = delete;
  JitSession& operator=(const JitSession&) = delete;

  /// The functions of a program, to be called in order with one spill array; empty if the program
  /// was not compiled (JitOptions::compiledPrograms).
  std::span<const ProgramFn> program(ModelProgram p) const { return parts_[programIndex(p)]; }
  /// Doubles of spill memory the program needs.
  uint32_t spillSlots(ModelProgram p) const { return spill_[programIndex(p)]; }

 private:
  struct Impl;
  JitSession();
  std::unique_ptr<Impl> impl_;
  PerProgram<std::vector<ProgramFn>> parts_;
  PerProgram<uint32_t> spill_{};
};

}  // namespace qdot::llvmbackend
