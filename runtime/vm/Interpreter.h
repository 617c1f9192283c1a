// The bytecode interpreter: runs one function of a bc::Module on a register file, and, when a
// result is not finite, re-runs it step by step to name the instruction (and so the equation and
// its file:line) where the first NaN or infinity came from.
#pragma once

#include <string>

#include "qdot/bytecode.h"
#include "qdot/model_adapter.hpp"

namespace qdot::vm {

/// What a function may read (the ABI adapter's call record). Pointers a function does not use may
/// be null (the validator guarantees each function loads only what its ABI entry point passes).
using Inputs = ModelCall;

/// Runs f. `registers` has f.registerCount entries with the constant pool preloaded in
/// [0, f.constants.size()); out has f.outputCount entries.
void execute(const bc::Function& f, double* registers, const Inputs& in, double* out);

/// The same, with the switch-dispatched loop (the fallback where computed goto is unavailable).
void executeWithSwitch(const bc::Function& f, double* registers, const Inputs& in, double* out);

/// A register file for f: registerCount entries, constants preloaded.
std::vector<double> makeRegisters(const bc::Function& f);

/// After a run whose outputs are not all finite: re-runs function `id` one instruction at a time
/// and describes the first non-finite output by the instruction its value came from, e.g.
/// "sqrt of a negative number (-0.25) in equation 3 (...) at model.qd:12". "" if all are finite.
std::string diagnose(const bc::Module& m, bc::FunctionId id, double* registers, const Inputs& in, double* out);

}  // namespace qdot::vm
