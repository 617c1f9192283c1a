// Text form of the LLVM IR of a KernelModule (`--emit=llvm`, golden tests). No LLVM type here.
#pragma once

#include <cstdint>
#include <iosfwd>

#include "kernel/Kernel.h"

namespace qdot::llvmbackend {

/// Writes the LLVM module lowerKernels makes of `k` (Codegen.h): the functions the JIT compiles
/// and `qdot build` writes to its object file, every program with its external entry
/// `qdot_<program>`, split into parts of at most `maxInstructionsPerFunction` kernel instructions
/// (JitOptions::maxInstructionsPerFunction). This is the IR before code generation; the JIT runs
/// no IR pipeline by default (JitOptions::pipelineLevel 0). No target triple or data layout is
/// set, so the text is the same on every host.
void printIR(std::ostream& os, const kernel::KernelModule& k, uint32_t maxInstructionsPerFunction);

}  // namespace qdot::llvmbackend
