// Why a compiled program produced a non-finite output (internal to compiler/llvm): the program is
// re-run on the kernel IR, one instruction at a time, tracking where each non-finite value came
// from — the same diagnosis (and wording) as the VM's (runtime/vm/Interpreter.cpp).
#pragma once

#include <string>
#include <vector>

#include "kernel/Kernel.h"

namespace qdot::llvmbackend {

/// "sqrt of a negative number (-0.25) in equation 3 at model.qd:9", plus ", which makes <other
/// source> non-finite" for a shared value and " (computing <program>)" outside the residual.
/// `where[s]` is the location text of kernel source s ("model.qd:9", "" if none). "" if every
/// output is finite.
std::string diagnoseNonFinite(const kernel::KernelModule& m, kernel::ProgramId id, const kernel::Inputs& in,
                              const std::vector<std::string>& where);

}  // namespace qdot::llvmbackend
