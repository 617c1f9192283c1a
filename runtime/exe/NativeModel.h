// A QdotModel running compiled (ahead-of-time LLVM) programs, with names, pattern and the
// diagnosis of failures taken from a VM model of the same module.
#pragma once

#include "exe/Embedded.h"
#include "qdot/model_abi.h"

namespace qdot::exe {

/// Wraps `vm` (owned: destroyed with the result): the native programs compute, and when one yields a
/// non-finite value the VM re-runs the call to say which equation failed (lastError).
QdotModel* createNativeModel(QdotModel* vm, const qdot_program_fn programs[6], const uint32_t spill[6]);

}  // namespace qdot::exe
