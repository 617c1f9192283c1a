// Ahead-of-time code for standalone executables (`qdot build --backend llvm`): the same kernel
// functions the JIT compiles (Codegen.h, same target machine and level), written to a relocatable
// object file for the host. No LLVM type here.
#pragma once

#include <cstdint>
#include <string>

#include "kernel/Kernel.h"
#include "qdot/programs.hpp"
#include "qdot/result.hpp"

namespace qdot::llvmbackend {

/// What the code in an object file offers, per program.
struct ObjectFileInfo {
  /// "qdot_residual", ... (ProgramFn, Jit.h); "" for the programs that run once per simulation
  /// (parameters, start values), which the executable runs on its embedded bytecode, as the JIT
  /// leaves them to the interpreter (JitOptions::compiledPrograms): a component array's
  /// parameters are one straight-line store each, and compiling them took most of qdot build.
  PerProgram<std::string> entryNames;
  PerProgram<uint32_t> spillSlots{};   ///< doubles of scratch each needs
};

/// Compiles the programs of `k` that run per step for the host (position-independent) into the object file `path`;
/// what it offers, or why it could not be written.
Result<ObjectFileInfo> emitObjectFile(const kernel::KernelModule& k, int optLevel, const std::string& path);

}  // namespace qdot::llvmbackend
