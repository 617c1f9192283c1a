// The model ABI on top of the JIT: name tables as C string arrays built from the KernelModule,
// one spill buffer per program, and every entry point a thin wrapper that calls the compiled
// program and, if an output is not finite, re-runs the program on the kernel IR to say which
// equation produced it (Diagnose.h), stores that for lastError and returns 1.
#include "llvm/JitModel.h"

#include <algorithm>
#include <cmath>

#include "llvm/Diagnose.h"
#include "qdot/model_table.hpp"
#include "llvm/Jit.h"

namespace qdot::llvmbackend {
namespace {

using kernel::ProgramId;

struct JitModel : QdotModel {
  kernel::KernelModule kernels;
  std::vector<std::string> where;  // location text per kernel source
  std::unique_ptr<JitSession> session;
  mutable std::array<std::vector<double>, kernel::kProgramCount> spill;
  ModelNameTable names;  // what the table's name arrays point into
  std::vector<double> noneGiven;  // used when the runtime passes no given values
  std::vector<uint8_t> noneOverridden;
  mutable std::vector<double> startScratch;  // [y0 | yp0 | nominal]
  mutable std::string error;
};

const JitModel& self(const QdotModel* m) { return *static_cast<const JitModel*>(m); }


// The inputs of one call, as the compiled code and the kernel diagnosis both need them.
struct Call {
  double t = 0, cj = 0;
  const double *y = nullptr, *yp = nullptr, *p = nullptr, *given = nullptr;
  const uint8_t* overridden = nullptr;
};

kernel::Inputs kernelInputs(const JitModel& m, const Call& c) {
  size_t n = m.kernels.variableCount(), np = m.kernels.parameterNames.size();
  kernel::Inputs in;
  in.t = c.t, in.cj = c.cj;
  if (c.y) in.y = {c.y, n};
  if (c.yp) in.yp = {c.yp, n};
  if (c.p) in.p = {c.p, np};
  if (c.given) in.given = {c.given, np};
  if (c.overridden) in.overridden = {c.overridden, np};
  return in;
}

int run(const JitModel& m, ProgramId id, const Call& c, double* out) {
  const double tcj[2] = {c.t, c.cj};
  m.session->program(id)(tcj, c.y, c.yp, c.p, c.given, c.overridden, out, m.spill[static_cast<size_t>(id)].data());
  uint32_t count = m.kernels.program(id).outputCount;
  for (uint32_t i = 0; i < count; ++i)
    if (!std::isfinite(out[i])) {
      m.error = diagnoseNonFinite(m.kernels, id, kernelInputs(m, c), m.where);
      return 1;
    }
  return 0;
}

int parameters(const QdotModel* s, const double* given, const uint8_t* overridden, double* p) {
  const JitModel& m = self(s);
  Call c;
  c.given = given ? given : m.noneGiven.data();
  c.overridden = overridden ? overridden : m.noneOverridden.data();
  return run(m, ProgramId::Parameters, c, p);
}

int initialValues(const QdotModel* s, const double* p, double t0, double* y0, double* yp0, double* nominal) {
  const JitModel& m = self(s);
  Call c;
  c.t = t0, c.p = p;
  int rc = run(m, ProgramId::InitialValues, c, m.startScratch.data());
  size_t n = m.kernels.variableCount();
  const double* v = m.startScratch.data();
  if (y0) std::copy(v, v + n, y0);
  if (yp0) std::copy(v + n, v + 2 * n, yp0);
  if (nominal) std::copy(v + 2 * n, v + 3 * n, nominal);
  return rc;
}

int fixedStarts(const QdotModel* s, int32_t* fixed) {
  std::copy(self(s).kernels.fixed.begin(), self(s).kernels.fixed.end(), fixed);
  return 0;
}

Call stateCall(double t, const double* y, const double* yp, const double* p) {
  Call c;
  c.t = t, c.y = y, c.yp = yp, c.p = p;
  return c;
}

int residual(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* F) {
  return run(self(s), ProgramId::Residual, stateCall(t, y, yp, p), F);
}

int jacobian(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double cj,
             double* values) {
  Call c = stateCall(t, y, yp, p);
  c.cj = cj;
  return run(self(s), ProgramId::Jacobian, c, values);
}

int outputs(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  return run(self(s), ProgramId::Outputs, stateCall(t, y, yp, p), out);
}

int invariants(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  return run(self(s), ProgramId::Invariants, stateCall(t, y, yp, p), out);
}

const char* lastError(const QdotModel* s) { return self(s).error.c_str(); }

void destroy(QdotModel* s) { delete static_cast<JitModel*>(s); }

void fillTable(JitModel& m) {
  fillModelTable(m, m.names, m.kernels);
  m.parameters = parameters, m.initialValues = initialValues, m.fixedStarts = fixedStarts;
  m.residual = residual, m.jacobian = jacobian, m.outputs = outputs, m.invariants = invariants;
  m.lastError = lastError, m.destroy = destroy;
}

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
  m->noneGiven.assign(m->kernels.parameterNames.size(), 0.0);
  m->noneOverridden.assign(m->kernels.parameterNames.size(), 0);
  m->startScratch.assign(3 * m->kernels.variableCount(), 0.0);
  fillTable(*m);
  return m;
}

QdotModel* createJitModel(const kernel::KernelModule& k, const SourceManager& sm, int optLevel, std::string& error) {
  JitOptions options;
  options.optLevel = optLevel;
  return createJitModel(k, sm, options, error);
}

}  // namespace qdot::llvmbackend
