// The symbols `qdot build` generates for a standalone executable (one source file per model):
// the serialised bytecode module (bc::serialize), the model's experiment annotation and, with
// --backend llvm, the compiled programs (an object file emitted by compiler/llvm/ObjectFile.h).
#pragma once

#include <cstdint>

#include "qdot/programs.hpp"

extern "C" {
extern const uint8_t qdot_model_bytes[];
extern const uint64_t qdot_model_size;
/// start, stop, interval, tolerance; a value counts only where qdot_experiment_given is 1.
extern const double qdot_experiment_values[4];
extern const uint8_t qdot_experiment_given[4];

/// A compiled kernel program (compiler/llvm/Jit.h, ProgramFn): the call's inputs, out, spill.
typedef void (*qdot_program_fn)(const qdot::ModelCall* call, double* out, double* spill);
/// Per model program (qdot/programs.def order): the
/// native code, or all null when the model runs on the VM.
extern const qdot_program_fn qdot_native_programs[qdot::kModelProgramCount];
/// Doubles of spill memory each native program needs.
extern const uint32_t qdot_native_spill[qdot::kModelProgramCount];
}
