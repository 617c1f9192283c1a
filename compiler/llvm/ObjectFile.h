// Ahead-of-time code for standalone executables (`qdot build --backend llvm`): the same kernel
// functions the JIT compiles (Codegen.h, same target machine and level), written to a relocatable
// object file for the host. No LLVM type here.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "kernel/Kernel.h"

namespace qdot::llvmbackend {

/// What the code in an object file offers, per kernel::ProgramId.
struct ObjectFileInfo {
  std::array<std::string, kernel::kProgramCount> entryNames;  ///< "qdot_residual", ... (ProgramFn, Jit.h)
  std::array<uint32_t, kernel::kProgramCount> spillSlots{};   ///< doubles of scratch each needs
};

/// Compiles every program of `k` for the host (position-independent) into the object file `path`.
/// False with `error` on failure.
bool emitObjectFile(const kernel::KernelModule& k, int optLevel, const std::string& path, ObjectFileInfo& info,
                    std::string& error);

}  // namespace qdot::llvmbackend
