// The model ABI on top of the interpreter: one register file per function (constants preloaded
// at creation), name tables as C string arrays, and every entry point a thin wrapper that runs its
// program and, if a result is not finite, stores the diagnosis for lastError and returns 1.
#include <algorithm>
#include <cmath>

#include "qdot/model_table.hpp"
#include "vm/Interpreter.h"
#include "vm/Vm.h"

namespace qdot::vm {
namespace {

struct VmModel : QdotModel {
  bc::Module module;
  mutable std::array<std::vector<double>, bc::kFunctionCount> registers;
  ModelNameTable names;  // what the table's name arrays point into
  std::vector<double> noneGiven;     // used when the runtime passes no given values
  std::vector<uint8_t> noneOverridden;
  mutable std::vector<double> startScratch;  // [y0 | yp0 | nominal]
  mutable std::string error;
};

const VmModel& self(const QdotModel* m) { return *static_cast<const VmModel*>(m); }


int run(const VmModel& m, bc::FunctionId id, const Inputs& in, double* out) {
  const bc::Function& f = m.module.function(id);
  double* r = m.registers[static_cast<int>(id)].data();
  execute(f, r, in, out);
  for (uint32_t i = 0; i < f.outputCount; ++i)
    if (!std::isfinite(out[i])) {
      m.error = diagnose(m.module, id, r, in, out);
      return 1;
    }
  return 0;
}

int parameters(const QdotModel* s, const double* given, const uint8_t* overridden, double* p) {
  const VmModel& m = self(s);
  Inputs in;
  in.given = given ? given : m.noneGiven.data();
  in.overridden = overridden ? overridden : m.noneOverridden.data();
  return run(m, bc::FunctionId::Parameters, in, p);
}

int initialValues(const QdotModel* s, const double* p, double t0, double* y0, double* yp0, double* nominal) {
  const VmModel& m = self(s);
  Inputs in;
  in.t = t0, in.p = p;
  int rc = run(m, bc::FunctionId::InitialValues, in, m.startScratch.data());
  size_t n = m.module.variableNames.size();
  const double* v = m.startScratch.data();
  if (y0) std::copy(v, v + n, y0);
  if (yp0) std::copy(v + n, v + 2 * n, yp0);
  if (nominal) std::copy(v + 2 * n, v + 3 * n, nominal);
  return rc;
}

int fixedStarts(const QdotModel* s, int32_t* fixed) {
  std::copy(self(s).module.fixed.begin(), self(s).module.fixed.end(), fixed);
  return 0;
}

Inputs stateInputs(double t, const double* y, const double* yp, const double* p) {
  Inputs in;
  in.t = t, in.y = y, in.yp = yp, in.p = p;
  return in;
}

int residual(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* F) {
  return run(self(s), bc::FunctionId::Residual, stateInputs(t, y, yp, p), F);
}

int jacobian(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double cj,
             double* values) {
  Inputs in = stateInputs(t, y, yp, p);
  in.cj = cj;
  return run(self(s), bc::FunctionId::Jacobian, in, values);
}

int outputs(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  return run(self(s), bc::FunctionId::Outputs, stateInputs(t, y, yp, p), out);
}

int invariants(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  return run(self(s), bc::FunctionId::Invariants, stateInputs(t, y, yp, p), out);
}

const char* lastError(const QdotModel* s) { return self(s).error.c_str(); }

void destroy(QdotModel* s) { delete static_cast<VmModel*>(s); }

void fillTable(VmModel& m) {
  fillModelTable(m, m.names, m.module);
  m.parameters = parameters, m.initialValues = initialValues, m.fixedStarts = fixedStarts;
  m.residual = residual, m.jacobian = jacobian, m.outputs = outputs, m.invariants = invariants;
  m.lastError = lastError, m.destroy = destroy;
}

}  // namespace

QdotModel* createModel(const bc::Module& module, std::string& error) {
  if (!bc::validate(module, error)) return nullptr;
  auto* m = new VmModel();
  m->module = module;
  for (uint32_t f = 0; f < bc::kFunctionCount; ++f) m->registers[f] = makeRegisters(m->module.functions[f]);
  m->noneGiven.assign(m->module.parameterNames.size(), 0.0);
  m->noneOverridden.assign(m->module.parameterNames.size(), 0);
  m->startScratch.assign(3 * m->module.variableNames.size(), 0.0);
  fillTable(*m);
  return m;
}

QdotModel* createModelFromBytes(std::span<const uint8_t> bytes, std::string& error) {
  bc::Module module;
  if (!bc::deserialize(bytes, module, error)) return nullptr;
  return createModel(module, error);
}

}  // namespace qdot::vm
