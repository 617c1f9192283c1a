// NativeModel: the VM model's table with the six functions replaced by calls of the native code,
// checking outputs for non-finite values as the JIT model does (compiler/llvm/JitModel.cpp).
#include "exe/NativeModel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace qdot::exe {
namespace {

enum Program { kParameters, kInitialValues, kResidual, kJacobian, kOutputs, kInvariants };

struct NativeModel : QdotModel {
  QdotModel* vm = nullptr;
  std::array<qdot_program_fn, 6> programs{};
  mutable std::array<std::vector<double>, 6> spill;
  std::vector<double> noneGiven;
  std::vector<uint8_t> noneOverridden;
  mutable std::vector<double> scratch;  // initialValues: [y0 | yp0 | nominal]
  mutable std::string error;
};

const NativeModel& self(const QdotModel* m) { return *static_cast<const NativeModel*>(m); }

// After a native call: 0 if all `count` outputs are finite; else 1 with lastError from the VM's
// evaluation of the same call (which fails the same way), or a generic sentence.
template <typename VmCall>
int check(const NativeModel& m, const double* out, size_t count, const char* what, VmCall vmCall) {
  for (size_t i = 0; i < count; ++i)
    if (!std::isfinite(out[i])) {
      if (vmCall() != 0) m.error = m.vm->lastError(m.vm);
      else m.error = std::string(what) + " evaluated to a non-finite value";
      return 1;
    }
  return 0;
}

int parameters(const QdotModel* s, const double* given, const uint8_t* overridden, double* p) {
  const NativeModel& m = self(s);
  given = given ? given : m.noneGiven.data();
  overridden = overridden ? overridden : m.noneOverridden.data();
  const double tcj[2] = {0, 0};
  m.programs[kParameters](tcj, nullptr, nullptr, nullptr, given, overridden, p, m.spill[kParameters].data());
  return check(m, p, m.nParameters, "a parameter", [&] {
    std::vector<double> scratch(m.nParameters);
    return m.vm->parameters(m.vm, given, overridden, scratch.data());
  });
}

int initialValues(const QdotModel* s, const double* p, double t0, double* y0, double* yp0, double* nominal) {
  const NativeModel& m = self(s);
  const double tcj[2] = {t0, 0};
  double* v = m.scratch.data();
  size_t n = m.nVariables;
  m.programs[kInitialValues](tcj, nullptr, nullptr, p, nullptr, nullptr, v, m.spill[kInitialValues].data());
  if (y0) std::copy(v, v + n, y0);
  if (yp0) std::copy(v + n, v + 2 * n, yp0);
  if (nominal) std::copy(v + 2 * n, v + 3 * n, nominal);
  return check(m, v, 3 * n, "a start value", [&] {
    std::vector<double> a(n), b(n), c(n);
    return m.vm->initialValues(m.vm, p, t0, a.data(), b.data(), c.data());
  });
}

int fixedStarts(const QdotModel* s, int32_t* fixed) { return self(s).vm->fixedStarts(self(s).vm, fixed); }

using StateFn = int (*)(const QdotModel*, double, const double*, const double*, const double*, double*);

int state(const QdotModel* s, Program id, size_t count, StateFn vmFn, const char* what, double t, const double* y,
          const double* yp, const double* p, double* out) {
  const NativeModel& m = self(s);
  const double tcj[2] = {t, 0};
  m.programs[id](tcj, y, yp, p, nullptr, nullptr, out, m.spill[id].data());
  return check(m, out, count, what, [&] {
    std::vector<double> scratch(count);
    return vmFn(m.vm, t, y, yp, p, scratch.data());
  });
}

int residual(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* F) {
  return state(s, kResidual, s->nVariables, self(s).vm->residual, "a residual", t, y, yp, p, F);
}

int outputs(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  return state(s, kOutputs, s->nOutputs, self(s).vm->outputs, "an output", t, y, yp, p, out);
}

int invariants(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  return state(s, kInvariants, s->nInvariants, self(s).vm->invariants, "an invariant", t, y, yp, p, out);
}

int jacobian(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double cj,
             double* values) {
  const NativeModel& m = self(s);
  const double tcj[2] = {t, cj};
  m.programs[kJacobian](tcj, y, yp, p, nullptr, nullptr, values, m.spill[kJacobian].data());
  return check(m, values, m.jacobianNonzeros, "a Jacobian entry", [&] {
    std::vector<double> scratch(m.jacobianNonzeros);
    return m.vm->jacobian(m.vm, t, y, yp, p, cj, scratch.data());
  });
}

const char* lastError(const QdotModel* s) { return self(s).error.c_str(); }

void destroy(QdotModel* s) {
  auto* m = static_cast<NativeModel*>(s);
  m->vm->destroy(m->vm);
  delete m;
}

}  // namespace

QdotModel* createNativeModel(QdotModel* vm, const qdot_program_fn programs[6], const uint32_t spill[6]) {
  auto* m = new NativeModel();
  static_cast<QdotModel&>(*m) = *vm;  // sizes, names, pattern: pointers into the VM model
  m->vm = vm;
  for (int i = 0; i < 6; ++i) {
    m->programs[i] = programs[i];
    m->spill[i].assign(spill[i], 0.0);
  }
  m->noneGiven.assign(vm->nParameters, 0.0);
  m->noneOverridden.assign(vm->nParameters, 0);
  m->scratch.assign(3 * size_t(vm->nVariables), 0.0);
  m->parameters = parameters, m->initialValues = initialValues, m->fixedStarts = fixedStarts;
  m->residual = residual, m->jacobian = jacobian, m->outputs = outputs, m->invariants = invariants;
  m->lastError = lastError, m->destroy = destroy;
  return m;
}

}  // namespace qdot::exe
