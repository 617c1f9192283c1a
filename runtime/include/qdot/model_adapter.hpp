// ModelAdapter: the QdotModel entry points (parameters, start values, residual, Jacobian, outputs,
// invariants, lastError, destroy) for any backend that can run "program k on these inputs". The VM
// and the LLVM JIT implement only `run`; the ABI glue (default parameter inputs, splitting the start
// values, argument plumbing) lives here once.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "qdot/model_abi.h"
#include "qdot/model_table.hpp"
#include "qdot/programs.hpp"

namespace qdot {

/// Calls program `program` of any model through its ABI table (the inverse of ModelAdapter);
/// `out` has ModelDescription::outputCount(program) values. Used to re-run a call on another backend.
inline int callProgram(const QdotModel& m, ModelProgram program, const ModelCall& c, double* out) {
  size_t n = m.nVariables;
  switch (program) {
    case ModelProgram::Parameters: return m.parameters(&m, c.given, c.overridden, out);
    case ModelProgram::InitialValues: return m.initialValues(&m, c.p, c.t, out, out + n, out + 2 * n);
    case ModelProgram::Residual: return m.residual(&m, c.t, c.y, c.yp, c.p, out);
    case ModelProgram::Jacobian: return m.jacobian(&m, c.t, c.y, c.yp, c.p, c.cj, out);
    case ModelProgram::Outputs: return m.outputs(&m, c.t, c.y, c.yp, c.p, out);
    case ModelProgram::Invariants: return m.invariants(&m, c.t, c.y, c.yp, c.p, out);
  }
  return 1;
}

/// State every adapted model carries next to its backend data.
struct AdaptedModel : QdotModel {
  ModelNameTable names;                      ///< what the table's name arrays point into
  const int32_t* fixedFlags = nullptr;       ///< [nVariables], owned by the backend's description
  std::vector<double> noneGiven;             ///< used when the runtime passes no given values
  std::vector<uint8_t> noneOverridden;
  /// [y0 | yp0 | nominal], sized by the first initialValues call: a second tier (the background
  /// JIT) never makes one, and at 10⁶ unknowns it would be 48 MB written for nothing.
  mutable std::vector<double> startScratch;
  mutable std::string error;                 ///< lastError
};

/// `Model` derives from AdaptedModel and has `int run(ModelProgram, const ModelCall&, double* out) const`
/// returning nonzero (with `error` set) when an output is not finite.
template <class Model>
struct ModelAdapter {
  /// Points the table of `m` at `description` (names, pattern; it must outlive `m`) and its
  /// functions here.
  static void install(Model& m, const ModelDescription& description) {
    fillModelTable(m, m.names, description);
    m.fixedFlags = description.fixed.data();
    m.noneGiven.assign(m.nParameters, 0.0);
    m.noneOverridden.assign(m.nParameters, 0);
    m.parameters = parameters, m.initialValues = initialValues, m.fixedStarts = fixedStarts;
    m.residual = residual, m.jacobian = jacobian, m.outputs = outputs, m.invariants = invariants;
    m.lastError = lastError, m.destroy = destroy;
  }

 private:
  static const Model& self(const QdotModel* s) { return *static_cast<const Model*>(s); }

  static ModelCall state(double t, const double* y, const double* yp, const double* p) {
    ModelCall c;
    c.t = t, c.y = y, c.yp = yp, c.p = p;
    return c;
  }

  static int parameters(const QdotModel* s, const double* given, const uint8_t* overridden, double* p) {
    const Model& m = self(s);
    ModelCall c;
    c.given = given ? given : m.noneGiven.data();
    c.overridden = overridden ? overridden : m.noneOverridden.data();
    return m.run(ModelProgram::Parameters, c, p);
  }

  static int initialValues(const QdotModel* s, const double* p, double t0, double* y0, double* yp0, double* nominal) {
    const Model& m = self(s);
    ModelCall c;
    c.t = t0, c.p = p;
    m.startScratch.resize(3 * size_t{m.nVariables});
    int rc = m.run(ModelProgram::InitialValues, c, m.startScratch.data());
    const double* v = m.startScratch.data();
    size_t n = m.nVariables;
    if (y0) std::copy(v, v + n, y0);
    if (yp0) std::copy(v + n, v + 2 * n, yp0);
    if (nominal) std::copy(v + 2 * n, v + 3 * n, nominal);
    return rc;
  }

  static int fixedStarts(const QdotModel* s, int32_t* fixed) {
    std::copy(self(s).fixedFlags, self(s).fixedFlags + s->nVariables, fixed);
    return 0;
  }

  static int residual(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* F) {
    return self(s).run(ModelProgram::Residual, state(t, y, yp, p), F);
  }

  static int jacobian(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double cj,
                      double* values) {
    ModelCall c = state(t, y, yp, p);
    c.cj = cj;
    return self(s).run(ModelProgram::Jacobian, c, values);
  }

  static int outputs(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
    return self(s).run(ModelProgram::Outputs, state(t, y, yp, p), out);
  }

  static int invariants(const QdotModel* s, double t, const double* y, const double* yp, const double* p,
                        double* out) {
    return self(s).run(ModelProgram::Invariants, state(t, y, yp, p), out);
  }

  static const char* lastError(const QdotModel* s) { return self(s).error.c_str(); }
  static void destroy(QdotModel* s) { delete static_cast<Model*>(s); }
};

}  // namespace qdot
