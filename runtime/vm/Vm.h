// The VM's public API: a QdotModel (runtime/include/qdot/model_abi.h) implemented by interpreting
// a bytecode module, and the disassembler behind `--emit=bytecode`.
#pragma once

#include <iosfwd>
#include <span>

#include "qdot/bytecode.h"
#include "qdot/result.hpp"

namespace qdot::vm {

/// A model running `module`, or why the module does not validate. One instance must not
/// be called from two threads at once (it owns its register files); create one per thread instead.
Result<ModelPtr> createModel(bc::Module module);
/// The same from serialised bytes (bc::serialize).
Result<ModelPtr> createModelFromBytes(std::span<const uint8_t> bytes);
/// The module a model made by createModel runs (valid as long as the model): what a model that
/// runs the same module otherwise (an executable's native code) reads instead of a copy of its
/// description and index tables, which a large model's are. `model` must come from createModel.
const bc::Module& moduleOf(const QdotModel& model);

/// Text of every function: constants, then one instruction per line with its word offset and,
/// whenever it changes, the source it serves. Deterministic.
void disassemble(std::ostream& os, const bc::Module& m);
/// One function of m.
void disassembleFunction(std::ostream& os, const bc::Module& m, ModelProgram program);

}  // namespace qdot::vm
