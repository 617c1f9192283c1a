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
  PerProgram<std::string> entryNames;  ///< "qdot_residual", ... (ProgramFn, Jit.h)
  PerProgram<uint32_t> spillSlots{};   ///< doubles of scratch each needs
};

/// Compiles every program of `k` for the host (position-independent) into the object file `path`;
/// what it offers, or why it could not be written.
Result<ObjectFileInfo> emitObjectFile(const kernel::KernelModule& k, int optLevel, const std::string& path);

}  // namespace qdot::llvmbackend
