// The model ABI on top of the JIT: one spill buffer per program; the entry points come from
// ModelAdapter, this file only calls a compiled program (or interprets one that runs once per
// simulation and was not worth compiling) and, if an output is not finite, re-runs it
// on the kernel IR to say which equation produced it (Diagnose.h), stores that for lastError and
// returns 1.
#include "llvm/JitModel.h"

#include <algorithm>
#include <cmath>

#include "llvm/Diagnose.h"
#include "qdot/model_adapter.hpp"
#include "llvm/Jit.h"

namespace qdot::llvmbackend {
namespace {

using kernel::ProgramId;

using Call = ModelCall;

// The kernel interpreter's view of a call (for tracing a non-finite result to its equation).
kernel::Inputs kernelInputs(const kernel::KernelModule& k, const Call& c) {
  size_t n = k.variableCount(), np = k.parameterNames.size();
  kernel::Inputs in;
  in.t = c.t, in.cj = c.cj;
  if (c.y) in.y = {c.y, n};
  if (c.yp) in.yp = {c.yp, n};
  if (c.p) in.p = {c.p, np};
  if (c.given) in.given = {c.given, np};
  if (c.overridden) in.overridden = {c.overridden, np};
  return in;
}

struct JitModel : AdaptedModel {
  kernel::KernelModule kernels;
  std::vector<std::string> where;  // location text per kernel source
  std::unique_ptr<JitSession> session;
  mutable std::array<std::vector<double>, kernel::kProgramCount> spill;

  /// Calls the compiled program (its parts in order), or interprets one that was not compiled; a
  /// non-finite result is traced on the kernel IR for lastError.
  int run(ModelProgram program, const Call& c, double* out) const {
    auto id = static_cast<ProgramId>(program);
    const double tcj[2] = {c.t, c.cj};
    double* scratch = spill[static_cast<size_t>(id)].data();
    std::span<const ProgramFn> parts = session->program(id);
    if (parts.empty()) kernel::interpret(kernels.program(id), kernelInputs(kernels, c), {out, kernels.program(id).outputCount});
    for (ProgramFn part : parts) part(tcj, c.y, c.yp, c.p, c.given, c.overridden, out, scratch);
    uint32_t count = kernels.program(id).outputCount;
    for (uint32_t i = 0; i < count; ++i)
      if (!std::isfinite(out[i])) {
        error = diagnoseNonFinite(kernels, id, kernelInputs(kernels, c), where);
        return 1;
      }
    return 0;
  }
};

static_assert(static_cast<int>(ProgramId::Invariants) == static_cast<int>(ModelProgram::Invariants),
              "kernel::ProgramId must number the programs in model-ABI order");

// The sizes the ABI relies on (a malformed module would make compiled code write out of bounds).
bool validate(const kernel::KernelModule& k, std::string& error) {
  size_t n = k.variableCount();
  const size_t expected[kernel::kProgramCount] = {k.parameterNames.size(), 3 * n, n, k.jacobianRowIndices.size(),
                                                  k.outputNames.size(), k.invariantNames.size()};
  for (size_t i = 0; i < kernel::kProgramCount; ++i)
    if (k.programs[i].outputCount != expected[i]) {
      error = "kernel program " + k.programs[i].name + " writes " + std::to_string(k.programs[i].outputCount) +
              " values, the model ABI expects " + std::to_string(expected[i]);
      return false;
    }
  if (k.jacobianColumnStarts.size() != n + 1 || k.isDifferential.size() != n || k.fixed.size() != n) {
    error = "kernel module: Jacobian pattern or variable flags do not match the variable count";
    return false;
  }
  return true;
}

}  // namespace

QdotModel* createJitModel(const kernel::KernelModule& k, const SourceManager& sm, const JitOptions& options,
                          std::string& error, JitStats* stats) {
  if (!validate(k, error)) return nullptr;
  auto session = JitSession::compile(k, options, error, stats);
  if (!session) return nullptr;
  auto* m = new JitModel();
  m->kernels = k;
  for (const kernel::Source& s : k.sources) m->where.push_back(kernel::describeLocation(sm, s.range));
  m->session = std::move(session);
  for (size_t i = 0; i < kernel::kProgramCount; ++i)
    m->spill[i].assign(m->session->spillSlots(static_cast<ProgramId>(i)), 0.0);
  ModelAdapter<JitModel>::install(*m, m->kernels);
  return m;
}

}  // namespace qdot::llvmbackend
