// A QdotModel running ahead-of-time compiled programs (qdot build --backend llvm), on the ABI glue
// of ModelAdapter; names and pattern come from the embedded bytecode module, and when native code
// yields a non-finite value the VM re-runs the call to say which equation failed (lastError).
#pragma once

#include <span>
#include <string>

#include "exe/Embedded.h"
#include "qdot/bytecode.h"
#include "qdot/model_abi.h"
#include "qdot/result.hpp"

namespace qdot::exe {

/// A model of the serialised module `bytes` whose programs run as `programs` (with `spill` doubles
/// of scratch each), or why the bytes are not a valid module.
Result<ModelPtr> createNativeModel(std::span<const uint8_t> bytes, const qdot_program_fn programs[kModelProgramCount],
                                   const uint32_t spill[kModelProgramCount]);
/// The module a model made by createNativeModel reads its description from (valid as long as the
/// model), as vm::moduleOf for the VM's.
const bc::Module& moduleOf(const QdotModel& model);

}  // namespace qdot::exe
