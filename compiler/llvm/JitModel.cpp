// The model ABI on top of the JIT: one spill buffer per program; the entry points come from
// ModelAdapter, this file only calls a compiled program (or interprets one that runs once per
// simulation and was not worth compiling) and, if an output is not finite, re-runs it on the
// kernel IR with the shared diagnosis (qdot/non_finite.hpp) to say which equation produced it,
// stores that for lastError and returns 1.
#include "llvm/JitModel.h"

#include <cmath>

#include "llvm/Jit.h"
#include "qdot/model_adapter.hpp"
#include "qdot/non_finite.hpp"

namespace qdot::llvmbackend {
namespace {

// A kernel program as the diagnosis reads it: instruction i defines register i; `ldk` loads the pool.
ProgramTrace traceOf(const kernel::Program& p) {
  ProgramTrace trace;
  for (uint32_t i = 0; i < p.code.size(); ++i) {
    const kernel::Instr& ins = p.code[i];
    trace.code.push_back({static_cast<bc::Opcode>(ins.op), i, ins.a, ins.b, ins.c, ins.imm});
    trace.sources.push_back(ins.source);
  }
  trace.constants = p.constants;
  trace.registerCount = static_cast<uint32_t>(p.code.size());
  trace.loops = p.loops;
  trace.indexTable = p.indexTable;
  return trace;
}

struct JitModel : AdaptedModel {
  std::shared_ptr<const kernel::KernelModule> kernels;
  std::vector<bc::Location> locations;  // per kernel source, for the diagnosis
  std::unique_ptr<JitSession> session;
  mutable PerProgram<std::vector<double>> spill;

  /// Calls the compiled program (its parts in order), or interprets one that was not compiled; a
  /// non-finite result is traced on the kernel IR for lastError.
  int run(ModelProgram program, const ModelCall& c, double* out) const {
    const kernel::Program& code = kernels->program(program);
    double* scratch = spill[programIndex(program)].data();
    std::span<const ProgramFn> parts = session->program(program);
    if (parts.empty()) kernel::interpret(code, c, {out, code.outputCount});
    for (ProgramFn part : parts) part(&c, out, scratch);
    for (uint32_t i = 0; i < code.outputCount; ++i)
      if (!std::isfinite(out[i])) {
        error = diagnoseNonFinite(kernels->description, locations, program, traceOf(code), c);
        return 1;
      }
    return 0;
  }
};

// The sizes the ABI relies on and the loop rules (a malformed module would make compiled code
// write out of bounds).
Status validate(const kernel::KernelModule& k) {
  for (size_t i = 0; i < kModelProgramCount; ++i) {
    size_t expected = k.description->outputCount(programAt(i));
    if (k.programs[i].outputCount != expected)
      return Error{"kernel program " + k.programs[i].name + " writes " + std::to_string(k.programs[i].outputCount) +
                   " values, the model ABI expects " + std::to_string(expected)};
    std::string e = kernel::checkLoops(k.programs[i], k.variableCount(), k.description->parameterCount());
    if (!e.empty()) return Error{"kernel program " + k.programs[i].name + ": " + e};
  }
  if (std::string e = k.description->inconsistency(); !e.empty()) return Error{"kernel module: " + e};
  return {};
}

// The options with the programs that run once added where JitOptions::compileRunOnceFrom says.
JitOptions withLongRunOncePrograms(const kernel::KernelModule& k, JitOptions options) {
  for (ModelProgram once : {ModelProgram::Parameters, ModelProgram::InitialValues}) {
    uint64_t executed = kernel::executedInstructions(k.program(once));
    if (executed >= options.compileRunOnceFrom && executed >= kRunOnceRepeats * k.program(once).code.size())
      options.compiledPrograms |= programBit(once);
  }
  return options;
}

}  // namespace

Result<ModelPtr> createJitModel(const kernel::KernelModule& k, const SourceManager& sm, const JitOptions& options,
                                JitStats* stats) {
  return createJitModel(std::make_shared<const kernel::KernelModule>(k), sm, options, stats);
}

Result<ModelPtr> createJitModel(std::shared_ptr<const kernel::KernelModule> k, const SourceManager& sm,
                                const JitOptions& options, JitStats* stats) {
  if (Status valid = validate(*k); !valid) return Error{valid.error()};
  // The model holds the kernels it was compiled from: the code reads their index tables in place.
  auto session = JitSession::compile(*k, withLongRunOncePrograms(*k, options), stats);
  if (!session) return Error{session.error()};
  auto m = std::make_unique<JitModel>();
  m->kernels = std::move(k);
  for (const kernel::Source& s : m->kernels->sources)
    m->locations.push_back({s.label, kernel::describeLocation(sm, s.range), s.text});
  m->session = std::move(session).value();
  for (size_t i = 0; i < kModelProgramCount; ++i) m->spill[i].assign(m->session->spillSlots(programAt(i)), 0.0);
  ModelAdapter<JitModel>::install(*m, m->kernels->description);
  return ModelPtr(m.release());
}

}  // namespace qdot::llvmbackend
