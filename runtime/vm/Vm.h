// The VM's public API: a QdotModel (runtime/include/qdot/model_abi.h) implemented by interpreting
// a bytecode module, and the disassembler behind `--emit=bytecode`.
#pragma once

#include <iosfwd>
#include <span>
#include <string>

#include "qdot/bytecode.h"
#include "qdot/model_abi.h"

namespace qdot::vm {

/// A model running `module` (copied). Returns nullptr, with `error` set, if the module does not
/// validate. Release it with model->destroy(model). One instance must not be called from two
/// threads at once (it owns its register files); create one per thread instead.
QdotModel* createModel(const bc::Module& module, std::string& error);
/// The same from serialised bytes (bc::serialize).
QdotModel* createModelFromBytes(std::span<const uint8_t> bytes, std::string& error);

/// Text of every function: constants, then one instruction per line with its word offset and,
/// whenever it changes, the source it serves. Deterministic.
void disassemble(std::ostream& os, const bc::Module& m);
/// One function of m.
void disassembleFunction(std::ostream& os, const bc::Module& m, bc::FunctionId id);

}  // namespace qdot::vm
