// The bytecode interpreter: runs one function of a bc::Module on a register file. When a result
// is not finite, the model (Model.cpp) hands the function, decoded by `traceOf`, to the shared
// diagnosis (qdot/non_finite.hpp) to name the instruction, and so the equation and its file:line,
// where the first NaN or infinity came from.
#pragma once

#include <vector>

#include "qdot/bytecode.h"
#include "qdot/non_finite.hpp"
#include "qdot/programs.hpp"

namespace qdot::vm {

/// Runs f on `in` (pointers a function does not use may be null: the validator guarantees each
/// function loads only what its ABI entry point passes). `registers` has f.registerCount entries
/// with the constant pool preloaded in [0, f.constants.size()); out has f.outputCount entries.
void execute(const bc::Function& f, double* registers, const ModelCall& in, double* out);

/// The same, with the switch-dispatched loop (the fallback where computed goto is unavailable).
void executeWithSwitch(const bc::Function& f, double* registers, const ModelCall& in, double* out);

/// A register file for f: registerCount entries, constants preloaded.
std::vector<double> makeRegisters(const bc::Function& f);

/// f decoded for diagnoseNonFinite (constants preloaded, as the VM runs it).
ProgramTrace traceOf(const bc::Function& f);

}  // namespace qdot::vm
